"""A jerk-limited plan whose rest is planned again from a move boundary, moving. The acceleration is
0 at every junction of an S-curve plan, so the planner's own state where a move ends — the
firmware's chain per axis, the position, the path speed — is all the moves after it need; the rest
goes on from that state, its first move entered at the speed the plan had there.

- A feed override on a running S-curve job (`replan_scurve_from`): the moves before the boundary are
  planned again exactly as they were, from the state the part they are in began from
  (`Plan.scurve_starts`, or the plan's start at rest; the same table and look-ahead: the same
  segments), then the rest at the new feeds.
- Lines added to an open job (`continue_scurve`): from a state its plan kept
  (`Plan.scurve_states`, planner/scurve_state.py), the plan's segments before it as they are, so
  that an addition costs the planning of what it changes, not of the whole job.

Either plan keeps its own states, for the next lines added."""

from __future__ import annotations

from array import array

from ..give_way import GIVE_WAY_MOVES, give_way
from ..protocol import Outputs
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
    if k % GIVE_WAY_MOVES == 0:
        give_way()  # planning onto a running job: the link's threads first
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
    begun: tuple[tuple[ScurveState, ...], float],
) -> Plan:
    """The whole plan from `start`: what the planner made (`moves`: its move ends, junctions and
    kept states; `begun`: the states its parts began from and the length of its moves)."""
    move_ends, junctions, kept = moves
    return Plan(
        config=scurve.config,
        segments=scurve.out,
        start=start,
        end=tuple(scurve.position),
        pauses=stops.pauses,
        moves=len(move_ends),
        distance_mm=begun[1],
        lines=rest.lines,
        max_landing_error=scurve.max_landing >> 18,
        move_ends=move_ends,
        retries=scurve.corrections,
        outputs=stops.outputs,
        peak_advance=tuple(scurve.peak),
        junctions=junctions,
        scurve_states=kept,
        scurve_starts=begun[0],
    )


class _Begun:
    """A planner going on from `state` of `plan` (or from the plan's start at rest: None), and the
    plan's move ends, junctions, pauses, outputs and the states its parts began from before it, as
    they were."""

    def __init__(self, plan: Plan, state: ScurveState | None, label: str) -> None:
        config = plan.config
        self.starts: tuple[ScurveState, ...] = ()
        if state is None:
            self.scurve = ScurvePlanner(config, plan.start, label)
            self.position, self.speed, self.distance_mm = plan.start, 0.0, 0.0
            self.move_ends, self.junctions = array("i"), array("d")
            self.pauses: list[tuple[int, int]] = []
            self.outputs: list[tuple[int, int, Outputs]] = []
            return
        assert isinstance(plan.segments, Stream)
        self.scurve = ScurvePlanner.resume(config, state, plan.segments.head(state.segments), label)
        self.position, self.speed, self.distance_mm = state.position, state.speed, state.distance_mm
        self.move_ends, self.junctions = plan.move_ends[: state.move], plan.junctions[: state.move]
        self.pauses = [p for p in plan.pauses if p[0] < state.segments]
        self.outputs = [o for o in plan.outputs if o[0] < state.segments]
        self.starts = (*(s for s in plan.scurve_starts if s.move < state.move), state)

    def stops(self, table: MoveTable) -> _Stops:
        """The stops of `table`, going on with the pauses and outputs before: the sections and the
        messages go on counting."""
        stops = _Stops(table, self.scurve.config, self.scurve.out, self.scurve)
        stops.pauses, stops.outputs = self.pauses, self.outputs
        return stops


def replan_scurve_from(
    plan: Plan,
    begin: ScurveState | None,
    planned: Program,
    move: int,
    rest: Program,
    label: str,
) -> Plan:
    """`plan` up to where its move `move` (≥ 1) begins, planned again as it was from `begin` (the
    state one of its parts began from at or before that move, or None: its start at rest) with
    `planned` (the program's items from there, as they were planned: the same table and look-ahead,
    the same segments), then `rest` going on from there, moving (JobError where it cannot: a stop
    the speed there cannot reach, no whole-tick profile)."""
    begun, config = _Begun(plan, begin, label), plan.config
    scurve, first = begun.scurve, len(begun.move_ends)
    before = build_moves(planned, config, begun.position, label)
    entry = junction_speeds(before, config, begun.speed)
    count = move - first
    stops = begun.stops(before)
    for k in range(count):
        _move(scurve, stops, before, k, entry, begun.move_ends)
    after = build_moves(rest, config, before.target[count - 1] if count else begun.position, label)
    junctions = begun.junctions + array(
        "d", entry[:count] + junction_speeds(after, config, scurve.speed)
    )
    distance = begun.distance_mm + float(sum(before.length[:count]))
    kept = _rest(scurve, begun.stops(after), after, junctions, begun.move_ends, distance)
    return _plan(
        plan.start,
        scurve,
        stops,
        (begun.move_ends, junctions, kept),
        rest,
        (begun.starts, distance + float(sum(after.length))),
    )


def continue_scurve(plan: Plan, state: ScurveState, rest: Program, label: str) -> Plan:
    """`plan` up to `state` (one of `plan.scurve_states`), then `rest` (the program's items from
    that move on, the added lines with them) going on from there, moving (JobError where it
    cannot)."""
    begun, config = _Begun(plan, state, label), plan.config
    after = build_moves(rest, config, state.position, label)
    junctions = begun.junctions + array("d", junction_speeds(after, config, state.speed))
    stops = begun.stops(after)
    kept = _rest(begun.scurve, stops, after, junctions, begun.move_ends, state.distance_mm)
    return _plan(
        plan.start,
        begun.scurve,
        stops,
        (begun.move_ends, junctions, kept),
        rest,
        (begun.starts, state.distance_mm + float(sum(after.length))),
    )
