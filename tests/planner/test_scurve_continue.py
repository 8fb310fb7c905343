"""Lines added to a jerk-limited open job go on from a state of the S-curve planner its plan kept,
from where its settled moves end (planner/scurve_state.py, scurve_rest.py): the plan's segments
before it as they are, then the rest planned from there, moving. The result is the plan of planning
up to that move again and the rest after it, segment for segment, and a chain of additions ends
where the whole program planned at once ends, within 2 % of its ticks."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.machine.move_items import MoveItems
from quadstep.machine.open_end import settled_moves
from quadstep.machine.override import continue_plan, feeds_at, prepare, replan_scurve
from quadstep.planner.lookahead import settled_moves as settled_junctions
from quadstep.planner.plan import plan_program
from quadstep.planner.program import Program
from quadstep.planner.scurve_state import KEPT_STATES

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
CONFIG = ROUTER.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in ROUTER.axes)}
)


def chords(count: int, length_mm: float = 0.05) -> str:
    """Chords of a circle, with a spindle change and a dwell among them."""
    out = ["G21 G90 G94 F2400", "G0 X70 Y50"]
    for k in range(1, count + 1):
        a = k * length_mm / 20.0
        out.append(f"G1 X{50 + 20 * math.cos(a):.4f} Y{50 + 20 * math.sin(a):.4f}")
        if k % 151 == 0:
            out.append("M3 S1000")
        if k % 263 == 0:
            out.append("G4 P0.05")
    return "\n".join(out) + "\n"


def program_of(text: str) -> Program:
    return parse_gcode(text, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)


def test_a_plan_keeps_its_planner_from_where_its_settled_moves_end() -> None:
    plan = plan_program(program_of(chords(300)), CONFIG)
    states = plan.scurve_states
    assert 0 < states[0].move < plan.moves - 10
    assert states[0].move == settled_junctions(plan.junctions, plan.moves) == settled_moves(plan)
    # every boundary after it, up to the end or KEPT_STATES of them
    assert [s.move for s in states] == list(
        range(states[0].move, min(plan.moves, states[0].move + KEPT_STATES))
    )
    assert [s.segments for s in states] == [plan.move_ends[s.move - 1] for s in states]
    # not kept without jerk limits: those plans go on from their residual chain
    assert plan_program(program_of(chords(300)), ROUTER).scurve_states == ()


def test_an_addition_is_the_plan_up_to_the_kept_state_and_the_rest_from_there() -> None:
    plan = plan_program(program_of(chords(300)), CONFIG)
    more = program_of(chords(420))
    state = plan.scurve_states[0]
    joined = continue_plan(more, plan, state, feeds_at(100), "line")
    again = replan_scurve(more, plan, state.move, feeds_at(100), feeds_at(100), "line")
    assert list(joined.segments.segments()) == list(again.segments.segments())
    assert list(joined.move_ends) == list(again.move_ends)
    assert joined.outputs == again.outputs and joined.pauses == again.pauses
    assert joined.end == again.end and joined.moves == again.moves == 421
    assert (joined.retries, joined.max_landing_error, joined.peak_advance) == (
        again.retries,
        again.max_landing_error,
        again.peak_advance,
    )
    assert joined.distance_mm == pytest.approx(again.distance_mm)
    # what the plan had before the state is the same objects, not planned again
    before = state.segments
    assert all(
        a is b
        for a, b in zip(joined.segments.segments(0, before), plan.segments.segments(0, before))
    )


@pytest.mark.parametrize("step", [7, 60, 151])
def test_a_chain_of_additions_ends_as_the_whole_program_planned_at_once(step: int) -> None:
    whole = program_of(chords(600))
    head = 40
    program = replace(whole, items=whole.items[:head])
    plan = plan_program(program, CONFIG)
    items = MoveItems(CONFIG, plan.start)
    for at in range(head, len(whole.items), step):
        program = replace(program, items=whole.items[: at + step])
        kept = plan.scurve_states[0]
        joined = continue_plan(program, plan, kept, feeds_at(100), "line", items)
        # what the plan had before its kept state goes out as it was
        assert list(joined.segments.segments(0, kept.segments)) == list(
            plan.segments.segments(0, kept.segments)
        )
        assert joined.scurve_states[0].move >= kept.move
        plan = joined
    at_once = plan_program(whole, CONFIG)
    assert plan.end == at_once.end and plan.moves == at_once.moves
    # not the same ticks: each addition enters its first move at the speed the plan reached there
    assert plan.segments.ticks == pytest.approx(at_once.segments.ticks, rel=0.02)
    assert [p[1] for p in plan.pauses] == [p[1] for p in at_once.pauses]
    assert [o[2] for o in plan.outputs] == [o[2] for o in at_once.outputs]


def test_an_addition_goes_on_from_the_first_kept_state_not_sent() -> None:
    plan = plan_program(program_of(chords(300)), CONFIG)
    more = program_of(chords(420))
    whole = plan_program(more, CONFIG)
    first, later = plan.scurve_states[0], plan.scurve_states[5]
    at = plan.move_ends[first.move - 1]
    swap = prepare(more, plan, at, len(plan), feeds_at(100), "line", None)
    assert swap is not None and swap.index == at
    assert swap.plan.moves == 421 and swap.plan.end == whole.end
    # the settled boundary sent already: from a later one, the moves before it as they were (slowing
    # towards the end they had), then the rest
    sent = plan.move_ends[later.move - 2] + 1
    swap = prepare(more, plan, sent, len(plan), feeds_at(100), "line", None)
    assert swap is not None and swap.index == plan.move_ends[later.move - 1]
    assert swap.plan.moves == 421 and swap.plan.end == whole.end
    index = swap.index
    assert list(swap.plan.segments.segments(0, index)) == list(plan.segments.segments(0, index))
    assert swap.plan.segments.ticks == pytest.approx(whole.segments.ticks, rel=0.02)
    # every kept boundary sent: the lines wait for the end and go on from rest
    end = plan.move_ends[plan.scurve_states[-1].move - 1] + 1
    assert prepare(more, plan, end, len(plan), feeds_at(100), "line", None) is None


def test_an_override_on_a_plan_of_several_parts_keeps_what_came_before_its_boundary() -> None:
    """A feed override plans the rest again from the part its boundary is in, from the state that
    part began from: the segments before the boundary are those sent, in every part (planned again
    from the plan's start they would not be: each began at the speed the one before reached)."""
    whole = program_of(chords(600))
    program = replace(whole, items=whole.items[:40])
    plan = plan_program(program, CONFIG)
    items = MoveItems(CONFIG, plan.start)
    for at in range(40, 400, 60):
        program = replace(program, items=whole.items[: at + 60])
        plan = continue_plan(program, plan, plan.scurve_states[0], feeds_at(100), "line", items)
    starts = [s.move for s in plan.scurve_starts]
    assert len(starts) == 6 and starts == sorted(starts)
    for move in (starts[0] - 1, starts[0], starts[1] + 3, starts[-1] + 1):
        again = replan_scurve(program, plan, move, feeds_at(10), feeds_at(100), "line", items)
        index = plan.move_ends[move - 1]
        assert list(again.segments.segments(0, index)) == list(plan.segments.segments(0, index))
        same = replan_scurve(program, plan, move, feeds_at(100), feeds_at(100), "line", items)
        assert again.end == plan.end and again.segments.ticks > same.segments.ticks
        assert [s.move for s in again.scurve_starts] == [s for s in starts if s <= move]
