"""What a job asks for, in machine coordinates, before any planning.

The G-code parser and the move-file loader both produce a Program; the
planner turns it into segments. Positions are absolute machine coordinates in
mm, one value per configured axis, in the configuration's axis order; a move
also carries the work offset it was written in, so that messages can name
the value its line gave.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from ..coordinates import WorkCoordinates

MAX_DWELL_S = 3600.0  # an hour; M0 waits for the operator as long as it takes


class JobError(ValueError):
    """A job that cannot run; the message names the line (or move) and what is wrong."""


@dataclass(frozen=True, slots=True)
class LinearMove:
    """A straight move to `target`; feed None means rapid (each axis's own maximum speed)."""

    line: int
    target: tuple[float, ...]
    feed: float | None  # mm/s along the path
    accel: float | None = None  # mm/s² along the path, None: the machine's limits only
    # machine − work per axis; () = none
    offset: tuple[float, ...] = field(default=(), compare=False)
    system: str = field(default="", compare=False)  # G54 … G59, or G53 for machine coordinates
    # mm the path may leave a corner by (G64 P); 0: exact stop (G61); None: config
    deviation: float | None = None

    def work(self, axis: int) -> float:
        """The target of `axis` as its line wrote it (work coordinates)."""
        return self.target[axis] - (self.offset[axis] if self.offset else 0.0)


@dataclass(frozen=True, slots=True)
class Dwell:
    """Stand still for `seconds` (the machine comes to rest first)."""

    line: int
    seconds: float


@dataclass(frozen=True, slots=True)
class Pause:
    """Come to rest and wait for the operator: M0, or a tool change (M6, `tool` the T word's
    number)."""

    line: int
    tool: int | None = None  # a tool change to this tool; None: a program pause (M0)
    coordinates: WorkCoordinates | None = field(default=None, compare=False)  # the program's, there

    @property
    def reason(self) -> str:
        return "M0" if self.tool is None else f"tool change to T{self.tool}"


@dataclass(frozen=True, slots=True)
class OutputState:
    """The spindle (or laser) and coolant as the program has set them: M3/M4/M5 with S, M7/M8/M9."""

    spindle: int = 5  # 3 (M3), 4 (M4) or 5 (M5: off)
    speed: float = 0.0  # S, in the units of the configuration's [spindle] s_max
    mist: bool = False  # M7
    flood: bool = False  # M8


@dataclass(frozen=True, slots=True)
class SetOutputs:
    """From here on the outputs are `state` (what follows runs under it; the machine does not
    stop)."""

    line: int
    state: OutputState


@dataclass(frozen=True, slots=True)
class ProbeMove:
    """G38.2–G38.5 toward `target` (machine mm) at `feed` (mm/s); the job comes to rest before it,
    probes, and `resume(rest position in machine mm)` is the rest of the program read from where the
    probe stopped."""

    line: int
    code: str  # "38.2" … "38.5"
    target: tuple[float, ...]
    feed: float
    resume: Callable[[Sequence[float]], Program] | None = field(default=None, compare=False)


Item = LinearMove | Dwell | Pause | SetOutputs | ProbeMove


@dataclass
class Program:
    """A parsed job: items in order, plus what the parser skipped and where the job ended."""

    items: list[Item] = field(default_factory=list)
    skipped: list[tuple[int, str]] = field(default_factory=list)  # (line, word)
    lines: int = 0  # source lines (or moves) read
    end_line: int | None = None  # line of M2/M30, if any
    after_end: int = 0  # lines with words after M2/M30, not run
    # the work coordinates as the program leaves them (G-code)
    coordinates: WorkCoordinates | None = None
