"""Rasters in ordinary G-code: runs of G1 moves along X at one feed whose S changes, under a laser's
M3 or M4 (laser mode), as LightBurn, LaserGRBL and the Inkscape plug-ins write an engraving. Each
run becomes a raster row (planner/raster.py: a ramp, RASTER lines at the feed, a ramp), the rest
of the program is planned as ever, and the pieces join at rest.
"""

from __future__ import annotations

from array import array
from dataclasses import dataclass

from ..config import MachineConfig
from ..protocol import Output, Outputs
from ..protocol.cubic import CubicSegment
from ..protocol.segment import Segment
from .plan import Plan, plan_program
from .program import Item, LinearMove, OutputState, Program, SetOutputs
from .raster import RasterRow, row_segments
from .stream import Stream

MIN_RUN = 3  # moves: fewer is a cut, not a raster


@dataclass(frozen=True)
class Run:
    """Items first … last of a program (its moves along X at one feed, and the output changes
    between them): the row they burn, and the output state the program has after them."""

    first: int
    last: int
    row: RasterRow
    state: OutputState


def candidate_step(item: Item, at: tuple[float, ...], lit: bool) -> float:
    """The X step of a move a raster could hold (a G1 along X with the laser on), else 0."""
    if not lit or not isinstance(item, LinearMove) or item.feed is None:
        return 0.0
    if any(t != a for t, a in zip(item.target[1:], at[1:])):
        return 0.0
    return item.target[0] - at[0]


def lasing(state: OutputState | None, config: MachineConfig) -> bool:
    return state is not None and config.spindle.laser and state.spindle in (3, 4)


def _run_at(
    items: list[Item], first: int, at: tuple[float, ...], state: OutputState, config: MachineConfig
) -> Run | None:
    """The raster run that begins with move `first` (from `at`, under `state`), if one does."""
    move = items[first]
    assert isinstance(move, LinearMove)
    step, feed = move.target[0] - at[0], move.feed
    edges, powers, last = [at[0]], [], first
    origin, run_state, j = at, state, first
    while j < len(items):
        item = items[j]
        if isinstance(item, SetOutputs):
            run_state = item.state
        elif (
            isinstance(item, LinearMove)
            and item.feed == feed
            and (s := candidate_step(item, at, lasing(run_state, config))) != 0.0
            and (s > 0) == (step > 0)
        ):
            edges.append(item.target[0])
            powers.append(round(config.spindle.power(run_state.speed) / 257))
            at, last = item.target, j
        else:
            break
        j += 1
    if len(powers) < MIN_RUN or len(set(powers)) < 2 or feed is None:
        return None
    row = RasterRow(edges_mm=edges, powers=powers, at_mm=origin, feed_mm_s=feed)
    return Run(first=first, last=last, row=row, state=run_state)


def find_runs(program: Program, config: MachineConfig, start: tuple[float, ...]) -> list[Run]:
    """The program's raster runs, in order."""
    runs: list[Run] = []
    items = program.items
    state: OutputState | None = None
    at = start
    i = 0
    while i < len(items):
        item = items[i]
        if state is not None and candidate_step(item, at, lasing(state, config)) != 0.0:
            run = _run_at(items, i, at, state, config)
            if run is not None:
                runs.append(run)
                state = run.state
                at = (*run.row.edges_mm[-1:], *run.row.at_mm[1:])
                i = run.last + 1
                continue
        if isinstance(item, SetOutputs):
            state = item.state
        elif isinstance(item, LinearMove):
            at = item.target
        i += 1
    return runs


def _returns(items: list[Item]) -> bool:
    """Whether what follows a row needs the machine where the row's G-code left it: it cuts before
    it rapids, or the program ends there."""
    for item in items:
        if isinstance(item, LinearMove):
            return item.feed is not None
    return True


def plan_with_rasters(
    program: Program, config: MachineConfig, start: tuple[int, ...], label: str = "line"
) -> Plan | None:
    """The program with its raster runs as rows of RASTER lines, or None when it has none."""
    if config.jerk_limited:
        return None  # rows ramp at a constant acceleration
    runs = find_runs(program, config, config.to_mm(start))
    if not runs:
        return None
    segments: list[Segment | CubicSegment] = []
    outputs: list[tuple[int, int, Outputs]] = []
    pauses: list[tuple[int, int]] = []
    move_ends = array("i")
    position = tuple(start)
    state: OutputState | None = None
    done = 0
    back: tuple[float, ...] = ()
    for run in [*runs, None]:
        stop = run.first if run is not None else len(program.items)
        head: list[Item] = [SetOutputs(line=0, state=state)] if state is not None else []
        if done and _returns(program.items[done:stop]):
            # the program goes on from the row's end, where the overscan passed: back there, dark
            head.append(LinearMove(line=0, target=back, feed=None))
        piece = Program(items=head + program.items[done:stop], lines=program.lines)
        if piece.items:
            plan = plan_program(piece, config, position, label)
            base = len(segments)
            segments += plan.quadratic_segments()
            outputs += [(base + k, p + len(pauses), m) for k, p, m in plan.outputs]
            pauses += [(base + k, line) for k, line in plan.pauses]
            returned = len(head) - (state is not None)  # the return is not a move of the program
            move_ends.extend(base + e for e in plan.move_ends[returned:])
            position = plan.end
        if run is None:
            break
        outputs.append((len(segments), len(pauses), Outputs(outputs=int(Output.ON), power=0)))
        row, position, ends = row_segments(run.row, config, position)
        move_ends.extend(len(segments) + e for e in ends)  # a move per pixel
        segments += row
        outputs.append((len(segments), len(pauses), Outputs(outputs=0, power=0)))
        state, done = run.state, run.last + 1
        back = (run.row.edges_mm[-1], *run.row.at_mm[1:])
    stream = Stream(base=segments, axes=len(config.axes))
    for k in range(len(segments)):
        stream.add_base(k)
    return Plan(
        config=config,
        segments=stream,
        start=tuple(start),
        end=position,
        pauses=pauses,
        moves=len(move_ends),
        lines=program.lines,
        move_ends=move_ends,
        outputs=outputs,
    )
