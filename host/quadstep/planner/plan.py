"""Program → Plan: moves and limits, look-ahead, whole-tick profiles, exact segments."""

from __future__ import annotations

from array import array
from dataclasses import dataclass, field

import numpy as np

from ..config import MachineConfig
from ..give_way import GIVE_WAY_MOVES, give_way
from ..kernel.fixed import SIGMA, D
from ..protocol import Outputs
from ..protocol.segment import Segment
from .limits import check_duration
from .lookahead import PLAN_ACCEL_FRACTION, junction_speeds, settled_moves
from .moves import MoveTable, build_moves
from .outputs import is_dynamic, output_message, set_at_rest
from .profile import fit_profiles
from .program import Dwell, JobError, OutputState, Pause, ProbeMove, Program, SetOutputs
from .quantize import Quantizer
from .scurve import ScurvePlanner
from .scurve_state import ScurveState, StateKeeper
from .segments import SegmentArrays
from .stream import Stream


@dataclass(frozen=True)
class Boundary:
    """Where a plan goes on from another without stopping (a feed override): the residual chain's
    ideal (1/8192 step) and each axis's signed speed in the last segment there, and the path speed
    (mm/tick) the first move is entered at, as the plan before had it."""

    ideal2: tuple[int, ...]
    exit_speed: tuple[int, ...]
    speed: float

    @property
    def position(self) -> tuple[int, ...]:
        """The steppers there: at a move's end the ideal is within half a step of the target."""
        return tuple((i + D) // (2 * D) for i in self.ideal2)


@dataclass
class Plan:
    """A whole job, planned: its segments, where it starts and ends, and where it pauses."""

    config: MachineConfig
    # quadratic arrays; a stream of cubic segments when jerk-limited
    segments: SegmentArrays | Stream
    start: tuple[int, ...]
    end: tuple[int, ...]
    # (segment index, line) before which to wait
    pauses: list[tuple[int, int]] = field(default_factory=list)
    moves: int = 0
    distance_mm: float = 0.0
    lines: int = 0
    max_landing_error: int = 0  # largest |ideal − target| at a move end, in 1/8192 step
    move_ends: array = field(default_factory=lambda: array("i"))  # segments planned after each move
    retries: int = 0  # moves whose best profile would have missed a target by rounding
    # (segment index, pauses before it, message): OUTPUTS sent before that segment (at the end:
    # after the last)
    outputs: list[tuple[int, int, Outputs]] = field(default_factory=list)
    peak_advance: tuple[
        int, ...
    ] = ()  # jerk-limited plans: highest speed per axis, 2^-31 step per tick
    # each move's entry speed (mm/tick), then 0
    junctions: array = field(default_factory=lambda: array("d"))
    # a quadratic plan's residual chain at its end: each axis's ideal (1/8192 step), for going on
    # from a move near the end without summing every segment before it
    end_ideal2: tuple[int, ...] = ()
    # a jerk-limited plan's S-curve planner at move boundaries from where its settled moves end, for
    # lines added after its end to go on from (planner/scurve_state.py)
    scurve_states: tuple[ScurveState, ...] = ()
    # the states its parts began from, in order (lines added, an override, went on from each); none:
    # one part, from rest at `start`
    scurve_starts: tuple[ScurveState, ...] = ()

    def __len__(self) -> int:
        return len(self.segments)

    def quadratic_segments(self) -> list[Segment]:
        """Every segment of a plan without jerk limits, as protocol models (homing, probing and the
        backlash measurements stream them themselves; they take no cubic segments)."""
        assert isinstance(self.segments, SegmentArrays), "a jerk-limited plan has cubic segments"
        return [self.segments.segment(i) for i in range(len(self))]

    @property
    def duration_ticks(self) -> int:
        return int(np.sum(self.segments.numpy()["n"], dtype=np.int64))

    @property
    def duration_s(self) -> float:
        return self.duration_ticks / self.config.tick_hz

    def peak_speeds(self) -> list[float]:
        """Highest planned speed per axis, mm/s."""
        if isinstance(self.segments, Stream):
            return [
                i / SIGMA * self.config.tick_hz / axis.steps_per_mm
                for i, axis in zip(self.peak_advance, self.config.axes)
            ]
        arrays = self.segments.numpy()
        if len(self) == 0:
            return [0.0] * len(self.config.axes)
        top = np.maximum(arrays["v0"].max(axis=0), arrays["vn"].max(axis=0))
        return [
            float(top[i]) / D * self.config.tick_hz / axis.steps_per_mm
            for i, axis in enumerate(self.config.axes)
        ]


def plan_program(
    program: Program,
    config: MachineConfig,
    start: tuple[int, ...] | None = None,
    label: str = "line",
    boundary: Boundary | None = None,
) -> Plan:
    """Plan every item of `program` from stepper positions `start` (default all 0), or, moving, from
    a `boundary` of another plan (quadratic plans only)."""
    begin = (
        boundary.position
        if boundary is not None
        else tuple(start)
        if start is not None
        else (0,) * len(config.axes)
    )
    table = build_moves(program, config, begin, label)
    if boundary is not None:
        give_way()  # planning onto a running job: the link's threads first, between the stages too
    return plan_moves(table, config, program.lines, label, boundary)


class _Stops:
    """The table's stops (dwells, pauses, probes, output changes), put into the plan as the moves
    reach them, and the OUTPUTS messages the plan sends."""

    def __init__(
        self,
        table: MoveTable,
        config: MachineConfig,
        out: SegmentArrays | Stream,
        timing: ScurvePlanner | Quantizer,
    ) -> None:
        self.config = config
        self.out = out
        self.timing = timing
        self.pauses: list[tuple[int, int]] = []
        self.outputs: list[tuple[int, int, Outputs]] = []
        self.state: OutputState | None = None  # None: the job sets no output
        self._stops = iter(table.stops)
        self._next = next(self._stops, None)

    def send(self, message: Outputs) -> None:
        if not self.outputs or self.outputs[-1][2] != message:
            self.outputs.append((len(self.out), len(self.pauses), message))

    def flush(self, before: int) -> None:
        """The stops before move `before`."""
        while self._next is not None and self._next[0] <= before:
            item = self._next[1]
            if isinstance(item, Dwell):
                self.timing.dwell(round(item.seconds * self.config.tick_hz), item.line)
            # a probe: the job probes there, then plans again
            elif isinstance(item, (Pause, ProbeMove)):
                if isinstance(self.timing, ScurvePlanner):
                    self.timing.stop(item.line)
                self.pauses.append((len(self.out), item.line))
            elif isinstance(item, SetOutputs):
                self.state = item.state
                if set_at_rest(self.state, self.config):
                    self.send(output_message(self.state, self.config))
            self._next = next(self._stops, None)


def _quantized_move(
    quantizer: Quantizer, table: MoveTable, k: int, entry: list[float], label: str
) -> int:
    """Move k in whole-tick segments, from the best profile that lands exactly; returns how many
    profiles before it missed (retries)."""
    accel = table.accel[k]
    profiles = fit_profiles(
        table.length[k],
        entry[k],
        entry[k + 1],
        table.max_speed[k],
        accel,
        accel * PLAN_ACCEL_FRACTION,
    )
    for attempt, profile in enumerate(profiles):
        if quantizer.move(table.target[k], table.length[k], profile, table.line[k]):
            return attempt
        if quantizer.move(
            table.target[k], table.length[k], profile, table.line[k], continuous=False
        ):
            return attempt
    raise JobError(
        f"{label} {table.line[k]}: no whole-tick profile lands this move exactly; lower max_speed"
    )


def plan_moves(
    table: MoveTable,
    config: MachineConfig,
    lines: int = 0,
    label: str = "line",
    boundary: Boundary | None = None,
) -> Plan:
    if boundary is not None and config.jerk_limited:
        raise JobError("a jerk-limited plan goes on only from rest")
    check_duration(table, config, label)  # each move at its top speed, before the look-ahead
    if boundary is not None:
        give_way()
    entry = junction_speeds(table, config, boundary.speed if boundary is not None else 0.0)
    if boundary is not None:
        give_way()
    check_duration(table, config, label, entry)  # with its ramps: before anything is planned
    scurve = ScurvePlanner(config, table.start, label) if config.jerk_limited else None
    out: SegmentArrays | Stream
    quantizer: Quantizer | None = None
    if scurve is not None:
        out = scurve.out
    else:
        arrays = SegmentArrays(len(config.axes))
        out, quantizer = arrays, Quantizer(arrays, table.start)
    # the residual chain and the speeds go on unbroken
    if quantizer is not None and boundary is not None:
        quantizer.ideal2, quantizer.exit_speed = list(boundary.ideal2), list(boundary.exit_speed)
    timing: ScurvePlanner | Quantizer | None = scurve if scurve is not None else quantizer
    assert timing is not None
    stops = _Stops(table, config, out, timing)
    move_ends = array("i")
    retries = 0
    keeper = StateKeeper(table, settled_moves(entry, len(table)))
    for k in range(len(table)):
        if boundary is not None and k % GIVE_WAY_MOVES == 0:
            give_way()  # planning onto a running job: the link's threads first
        if scurve is not None:  # where more lines could go on from
            keeper.before(scurve, k)
        stops.flush(k)
        if stops.state is not None and is_dynamic(stops.state, config):
            stops.send(output_message(stops.state, config, table.unit[k], table.feed[k]))
        if scurve is not None:
            scurve.move(table, k, entry)
        else:
            assert quantizer is not None
            retries += _quantized_move(quantizer, table, k, entry, label)
        move_ends.append(len(out))
    states = keeper.end(scurve) if scurve is not None else ()
    stops.flush(len(table))
    if scurve is not None:
        scurve.stop(table.line[-1] if len(table) else 0)
        return Plan(
            config=config,
            segments=out,
            start=table.start,
            end=tuple(scurve.position),
            pauses=stops.pauses,
            moves=len(table),
            distance_mm=float(sum(table.length)),
            lines=lines,
            max_landing_error=scurve.max_landing >> 18,
            move_ends=move_ends,
            retries=scurve.corrections,
            outputs=stops.outputs,
            peak_advance=tuple(scurve.peak),
            junctions=array("d", entry),
            scurve_states=states,
        )
    assert quantizer is not None
    return Plan(
        config=config,
        segments=out,
        start=table.start,
        end=tuple(quantizer.position),
        pauses=stops.pauses,
        moves=len(table),
        distance_mm=float(sum(table.length)),
        lines=lines,
        max_landing_error=quantizer.max_landing_error,
        move_ends=move_ends,
        retries=retries,
        outputs=stops.outputs,
        junctions=array("d", entry),
        end_ideal2=tuple(quantizer.ideal2),
    )
