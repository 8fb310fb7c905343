"""A jerk-limited plan whose rest is planned again from a move boundary, moving (a feed override on
a running S-curve job). The acceleration is 0 at every junction of an S-curve plan, so the planner's
own state where a move ends — the firmware's chain per axis, the position, the path speed — is all
the moves after it need: the moves before the boundary are planned again exactly as they were (the
same table and look-ahead: the same segments), and the rest goes on from that state, its first move
entered at the speed the plan had there."""

from __future__ import annotations

from array import array

from ..config import MachineConfig
from .lookahead import junction_speeds
from .moves import MoveTable, build_moves
from .outputs import is_dynamic, output_message
from .plan import Plan, _Stops
from .program import Program
from .scurve import ScurvePlanner


def _moves(
    scurve: ScurvePlanner,
    stops: _Stops,
    table: MoveTable,
    count: int,
    entry: list[float],
    move_ends: array,
) -> None:
    """The first `count` moves of `table`, with the stops before each."""
    config = scurve.config
    for k in range(count):
        stops.flush(k)
        if stops.state is not None and is_dynamic(stops.state, config):
            stops.send(output_message(stops.state, config, table.unit[k], table.feed[k]))
        scurve.move(table, k, entry)
        move_ends.append(len(scurve.out))


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
    _moves(scurve, stops, before, move, entry, move_ends)
    after = build_moves(rest, config, before.target[move - 1], label)
    pinned = junction_speeds(after, config, scurve.speed)
    rest_stops = _Stops(after, config, scurve.out, scurve)
    # one list of pauses and outputs: the sections and the messages go on counting
    rest_stops.pauses, rest_stops.outputs = stops.pauses, stops.outputs
    _moves(scurve, rest_stops, after, len(after), pinned, move_ends)
    rest_stops.flush(len(after))
    scurve.stop(after.line[-1] if len(after) else 0)
    return Plan(
        config=config,
        segments=scurve.out,
        start=before.start,
        end=tuple(scurve.position),
        pauses=stops.pauses,
        moves=move + len(after),
        distance_mm=float(sum(before.length[:move]) + sum(after.length)),
        lines=rest.lines,
        max_landing_error=scurve.max_landing >> 18,
        move_ends=move_ends,
        retries=scurve.corrections,
        outputs=stops.outputs,
        peak_advance=tuple(scurve.peak),
        junctions=array("d", list(entry[:move]) + list(pinned)),
    )
