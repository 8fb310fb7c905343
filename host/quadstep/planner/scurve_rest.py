"""A jerk-limited plan whose rest is planned again from a move boundary, moving. The acceleration is
0 at every junction of an S-curve plan, so the planner's own state where a move ends — the
firmware's chain per axis, the position, the path speed — is all the moves after it need; the rest
goes on from that state, its first move entered at the speed the plan had there.

- A feed override on a running S-curve job (`replan_scurve_from`): the moves before the boundary are
  planned again exactly as they were (the same table and look-ahead: the same segments), then the
  rest at the new feeds.
- Lines added to an open job (`continue_scurve`): from a state its plan kept
  (`Plan.scurve_states`, planner/scurve_state.py), the plan's segments before it as they are, so
  that an addition costs the planning of what it changes, not of the whole job.

Either plan keeps its own states, for the next lines added."""

from __future__ import annotations

from array import array

from ..config import MachineConfig
from .lookahead import junction_speeds, settled_moves
from .moves import MoveTable, build_moves
from .outputs import is_dynamic, output_message
from .plan import Plan, _Stops
from .program import Program
from .scurve import ScurvePlanner
from .scurve_state import ScurveState, StateKeeper
from .stream import Stream


def _move(
    scurve: ScurvePlanner,
    stops: _Stops,
    table: MoveTable,
    k: int,
    entry: list[float],
    move_ends: array,
) -> None:
    """Move k of `table`, with the stops before it."""
    stops.flush(k)
    if stops.state is not None and is_dynamic(stops.state, scurve.config):
        stops.send(output_message(stops.state, scurve.config, table.unit[k], table.feed[k]))
    scurve.move(table, k, entry)
    move_ends.append(len(scurve.out))


def _rest(
    scurve: ScurvePlanner,
    stops: _Stops,
    table: MoveTable,
    junctions: array,
    move_ends: array,
    distance_mm: float,
) -> tuple[ScurveState, ...]:
    """Every move of `table` after those planned before it (`move_ends`; `distance_mm` their
    length), its stops and the end at rest (`junctions`: every move's entry speed, the table's
    last). Returns the planner's states from where the settled moves end (the table's start if they
    end before it: the moves before it stay as they are)."""
    first = len(move_ends)
    entry = list(junctions[first:])
    settled = max(settled_moves(junctions, len(junctions) - 1), first)
    keeper = StateKeeper(table, settled, first, distance_mm)
    for k in range(len(table)):
        keeper.before(scurve, k)
        _move(scurve, stops, table, k, entry, move_ends)
    states = keeper.end(scurve)
    stops.flush(len(table))
    scurve.stop(table.line[-1] if len(table) else 0)
    return states


def _plan(
    start: tuple[int, ...],
    scurve: ScurvePlanner,
    stops: _Stops,
    moves: tuple[array, array, tuple[ScurveState, ...]],
    rest: Program,
    distance_mm: float,
) -> Plan:
    """The whole plan from `start`: what the planner made (`moves`: its move ends, junctions and
    kept states)."""
    move_ends, junctions, kept = moves
    return Plan(
        config=scurve.config,
        segments=scurve.out,
        start=start,
        end=tuple(scurve.position),
        pauses=stops.pauses,
        moves=len(move_ends),
        distance_mm=distance_mm,
        lines=rest.lines,
        max_landing_error=scurve.max_landing >> 18,
        move_ends=move_ends,
        retries=scurve.corrections,
        outputs=stops.outputs,
        peak_advance=tuple(scurve.peak),
        junctions=junctions,
        scurve_states=kept,
    )


def replan_scurve_from(
    planned: Program,
    start: tuple[int, ...],
    move: int,
    rest: Program,
    config: MachineConfig,
    label: str,
) -> Plan:
    """`planned` (the program as its plan was planned, from `start`) up to where its move `move`
    (≥ 1) begins, then `rest` going on from there, moving (JobError where it cannot: a stop the
    speed there cannot reach, no whole-tick profile)."""
    before = build_moves(planned, config, start, label)
    entry = junction_speeds(before, config)
    scurve = ScurvePlanner(config, before.start, label)
    stops = _Stops(before, config, scurve.out, scurve)
    move_ends = array("i")
    for k in range(move):
        _move(scurve, stops, before, k, entry, move_ends)
    after = build_moves(rest, config, before.target[move - 1], label)
    junctions = array("d", entry[:move] + junction_speeds(after, config, scurve.speed))
    rest_stops = _Stops(after, config, scurve.out, scurve)
    # one list of pauses and outputs: the sections and the messages go on counting
    rest_stops.pauses, rest_stops.outputs = stops.pauses, stops.outputs
    distance = float(sum(before.length[:move]))
    kept = _rest(scurve, rest_stops, after, junctions, move_ends, distance)
    return _plan(
        before.start,
        scurve,
        rest_stops,
        (move_ends, junctions, kept),
        rest,
        distance + float(sum(after.length)),
    )


def continue_scurve(plan: Plan, state: ScurveState, rest: Program, label: str) -> Plan:
    """`plan` up to `state` (one of `plan.scurve_states`), then `rest` (the program's items from
    that move on, the added lines with them) going on from there, moving (JobError where it
    cannot)."""
    config = plan.config
    assert isinstance(plan.segments, Stream)
    scurve = ScurvePlanner.resume(config, state, plan.segments.head(state.segments), label)
    after = build_moves(rest, config, state.position, label)
    junctions = plan.junctions[: state.move] + array(
        "d", junction_speeds(after, config, state.speed)
    )
    stops = _Stops(after, config, scurve.out, scurve)
    # what the plan sent before the state, as it was: the sections and the messages go on counting
    stops.pauses = [p for p in plan.pauses if p[0] < state.segments]
    stops.outputs = [o for o in plan.outputs if o[0] < state.segments]
    move_ends = plan.move_ends[: state.move]
    kept = _rest(scurve, stops, after, junctions, move_ends, state.distance_mm)
    return _plan(
        plan.start,
        scurve,
        stops,
        (move_ends, junctions, kept),
        rest,
        state.distance_mm + float(sum(after.length)),
    )
