"""A program started partway: its items from one on, after a safe approach from where the
machine is.

The program's items already carry everything the lines before the start
decided: units, distance mode, work offsets and G92, plane and arcs are
resolved into absolute machine targets, feeds are mm/s. What is left to
rebuild is what the machine itself holds: the outputs (spindle or laser,
coolant) and where the tool is. So the program from item `first` is

1. Z up to the clearance height (`safe_z`, else the top of Z's travel), at rapid;
2. the other axes over to where the item begins, at rapid;
3. the outputs as the program has them there, and the spindle's `spin_up_s`;
4. Z down to where the item begins, at the feed in force there;

(in laser mode the outputs come after 4: the beam stays off until the tool is
in place), then the items as written. A step of the approach that would not
move is left out. What follows a probe (G38.x) depends on where it stops, so
the program cannot start after one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..config import MachineConfig
from .program import (
    Dwell,
    Item,
    JobError,
    LinearMove,
    OutputState,
    Pause,
    ProbeMove,
    Program,
    SetOutputs,
)

MOTION = (LinearMove, ProbeMove)


@dataclass(frozen=True)
class Approach:
    """How a program started at its item `first` gets there: the items run before it, and what
    they do."""

    line: int  # the source line the program starts at (its first item's)
    rest: int  # the first item run as written (after the output changes folded in)
    items: tuple[Item, ...]  # lift, travel over, outputs (and spin-up), plunge
    begin: tuple[float, ...]  # machine mm where the rest begins
    moves: tuple[str, ...]  # its moves in order: "lift", "over", then "down" or "up"
    lift: float | None  # machine mm Z goes up to first; None: no lift
    outputs: OutputState | None  # the outputs restored; None: none set before
    spin_up_s: float  # the wait after the spindle is turned on
    feed: float | None  # mm/s of the plunge; None: rapid
    tool: Pause | None  # the last tool change before the start
    system: str  # the work system the rest begins in
    offset: tuple[float, ...]  # its offset (machine − work) per axis


def item_at_line(program: Program, line: int, label: str = "line") -> int:
    """The index of the first item of `program` from source line `line` on (a line that only sets
    modes or outputs, or is a comment, starts at the next line that does something)."""
    if line < 1:
        raise JobError(f"{label} {line}: {label}s are counted from 1")
    if line > program.lines:
        raise JobError(f"{label} {line} is past the end of the job ({program.lines} {label}s)")
    for index, item in enumerate(program.items):
        if item.line >= line:
            return index
    raise _nothing_moves(program, line, label)


def _nothing_moves(program: Program, line: int, label: str) -> JobError:
    last = next((item.line for item in reversed(program.items) if isinstance(item, MOTION)), None)
    where = "the job has no motion" if last is None else f"the last motion is at {label} {last}"
    return JobError(f"{label} {line}: nothing moves from here on ({where})")


def approach_to(
    program: Program,
    first: int,
    config: MachineConfig,
    at: Sequence[float],
    start: Sequence[float] | None = None,
    label: str = "line",
) -> Approach:
    """The approach from machine position `at` (mm) to `program`'s item `first`; `start` is where
    the program itself begins (default `at`). Raises JobError naming the line when the program
    cannot start there."""
    items = program.items
    shown = items[first].line if first < len(items) else program.lines
    probe = next((item for item in reversed(items[:first]) if isinstance(item, ProbeMove)), None)
    if probe is not None:
        raise JobError(
            f"{label} {shown} comes after the probe at {label} {probe.line} "
            f"(G{probe.code}): what follows depends on where it stops; start at "
            f"{label} {probe.line} or before it"
        )
    rest = first
    while rest < len(items) and isinstance(items[rest], SetOutputs):
        rest += 1  # output changes before the first motion are made by the approach
    motion = next((item for item in items[rest:] if isinstance(item, MOTION)), None)
    if motion is None:
        raise _nothing_moves(program, shown, label)
    begin = _begin(items[:first], at if start is None else start)
    state = next((i.state for i in reversed(items[:rest]) if isinstance(i, SetOutputs)), None)
    system: str = "G53"
    offset: tuple[float, ...] = ()
    if isinstance(motion, LinearMove):
        system, offset = motion.system or "G53", motion.offset
    tool = next(
        (i for i in reversed(items[:first]) if isinstance(i, Pause) and i.tool is not None), None
    )
    steps = _Path(config, at, motion.line, system, offset)
    lift = steps.lift(begin)
    steps.over(begin)
    feed = _plunge_feed(items, first, rest)
    spin_up = config.spindle.spin_up_s if _spinning(state, config) else 0.0
    outputs: list[Item] = []
    if state is not None:
        outputs.append(SetOutputs(motion.line, state))
        if spin_up > 0:
            outputs.append(Dwell(motion.line, spin_up))
    if not config.spindle.laser:
        steps.items += outputs
    steps.down(begin, feed)
    if config.spindle.laser:
        steps.items += outputs
    return Approach(
        line=shown,
        rest=rest,
        items=tuple(steps.items),
        begin=tuple(begin),
        moves=tuple(steps.moves),
        lift=lift,
        outputs=state,
        spin_up_s=spin_up,
        feed=feed,
        tool=tool,
        system=system,
        offset=offset,
    )


def program_from(
    program: Program,
    first: int,
    config: MachineConfig,
    at: Sequence[float],
    start: Sequence[float] | None = None,
    label: str = "line",
) -> Program:
    """`program` from its item `first` on, after the approach from machine position `at` (mm)."""
    approach = approach_to(program, first, config, at, start, label)
    return with_approach(program, approach)


def with_approach(program: Program, approach: Approach) -> Program:
    """`program`'s items from where `approach` leads, after it."""
    return replace(program, items=[*approach.items, *program.items[approach.rest :]])


def _begin(before: Sequence[Item], start: Sequence[float]) -> list[float]:
    """Where the machine is after `before`: the last move's target, else where the program began."""
    last = next((item for item in reversed(before) if isinstance(item, LinearMove)), None)
    return list(last.target if last is not None else start)


def _plunge_feed(items: Sequence[Item], first: int, rest: int) -> float | None:
    """The feed in force at item `first`: its motion's own if it cuts, else the last cut's before
    it, else the first cut's after it; None (rapid) for a job of rapids only."""

    def cut(item: Item) -> float | None:
        return item.feed if isinstance(item, MOTION) else None

    motion = next(item for item in items[rest:] if isinstance(item, MOTION))
    if cut(motion) is not None:
        return cut(motion)
    before = (f for f in map(cut, reversed(items[:first])) if f is not None)
    after = (f for f in map(cut, items[rest:]) if f is not None)
    return next(before, next(after, None))


def _spinning(state: OutputState | None, config: MachineConfig) -> bool:
    """The spindle (not a laser) is on at some speed."""
    if state is None or config.spindle.laser:
        return False
    return state.spindle != 5 and config.spindle.power(state.speed) > 0


class _Path:
    """The approach's moves, each added only when it moves a step."""

    def __init__(
        self,
        config: MachineConfig,
        at: Sequence[float],
        line: int,
        system: str,
        offset: tuple[float, ...],
    ) -> None:
        self.config = config
        self.position = list(at)
        self.line, self.system, self.offset = line, system, offset
        names = config.axis_names
        self.z = names.index("Z") if "Z" in names else None
        self.items: list[Item] = []
        self.moves: list[str] = []

    def _others_differ(self, begin: Sequence[float]) -> bool:
        here = self.config.to_steps(tuple(self.position))
        there = self.config.to_steps(tuple(begin))
        return any(a != b for i, (a, b) in enumerate(zip(here, there)) if i != self.z)

    def _go(
        self, kind: str, target: list[float], feed: float | None, machine: bool = False
    ) -> None:
        if self.config.to_steps(tuple(target)) == self.config.to_steps(tuple(self.position)):
            return
        self.moves.append(kind)
        offset, system = (self.offset, self.system)
        if machine:
            offset, system = (0.0,) * len(target), "G53"
        self.items.append(LinearMove(self.line, tuple(target), feed, offset=offset, system=system))
        self.position = target

    def lift(self, begin: Sequence[float]) -> float | None:
        """Z up to the clearance height when the other axes have somewhere to go: the height, or
        None when Z stays."""
        clearance = self.config.clearance_z
        if self.z is None or clearance is None or not self._others_differ(begin):
            return None
        height = max(clearance, self.position[self.z])
        before = len(self.items)
        target = [height if i == self.z else x for i, x in enumerate(self.position)]
        self._go("lift", target, None, machine=True)
        return height if len(self.items) > before else None

    def over(self, begin: Sequence[float]) -> None:
        """Every axis but Z to where the rest begins, at rapid."""
        target = [x if i == self.z else b for i, (x, b) in enumerate(zip(self.position, begin))]
        self._go("over", target, None)

    def down(self, begin: Sequence[float], feed: float | None) -> None:
        """Z to where the rest begins: down at `feed`, up at rapid."""
        if self.z is None:
            return
        lower = begin[self.z] < self.position[self.z]
        self._go("down" if lower else "up", list(begin), feed if lower else None)


def describe(approach: Approach, config: MachineConfig, label: str = "line") -> str:
    """What the approach does, for the operator: `starting at line 12: Z up to 0.000 mm (machine),
    X 10.000 Y 20.000 mm (G55) at rapid, …`."""
    names = config.axis_names
    offset = approach.offset or (0.0,) * len(names)
    work = [x - o for x, o in zip(approach.begin, offset)]
    system = f" ({approach.system})" if approach.system != "G53" else " (machine)"
    parts = []
    if approach.lift is not None:
        parts.append(f"Z up to {approach.lift:.3f} mm (machine)")
    if "over" in approach.moves:
        where = " ".join(f"{n} {x:.3f}" for n, x in zip(names, work) if n != "Z")
        parts.append(f"{where} mm{system} at rapid")
    outputs = _outputs_text(approach, config)
    last = approach.moves[-1] if approach.moves else None
    if last in ("down", "up"):
        feed = approach.feed if last == "down" else None
        speed = "rapid" if feed is None else f"F{feed * 60:g} mm/min"
        z = f"Z {last} to {work[names.index('Z')]:.3f} mm{system} at {speed}"
        parts += [z, *outputs] if config.spindle.laser else [*outputs, z]
    else:
        parts += outputs
    text = f"starting at {label} {approach.line}: " + (", ".join(parts) or "already there")
    tool = approach.tool
    if tool is not None:
        text += f"; tool T{tool.tool} ({label} {tool.line}) must be in the spindle"
    return text


def _outputs_text(approach: Approach, config: MachineConfig) -> list[str]:
    state = approach.outputs
    if state is None:
        return []
    what = "laser" if config.spindle.laser else "spindle"
    on = state.spindle != 5
    parts = [f"{what} M{state.spindle} S{state.speed:g} on" if on else f"{what} off (M5)"]
    coolant = [name for name, on in (("mist", state.mist), ("flood", state.flood)) if on]
    parts.append(f"{' and '.join(coolant)} coolant on" if coolant else "coolant off")
    if approach.spin_up_s > 0:
        parts.append(f"{approach.spin_up_s:g} s spin-up")
    return parts
