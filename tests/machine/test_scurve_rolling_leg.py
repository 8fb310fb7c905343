"""A long jerk-limited open job lets go of what the board has run (machine/rebase.py): its plan,
stream and program begin again where a part of it began (an addition went on from there: the S-curve
planner's state there is kept, Plan.scurve_starts). What comes after is what would have come: lines
added and overrides plan the same segments from there, and the emulator's trace is the prediction of
every stream in turn."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from host_helpers import assert_trace_is_prediction
from rolling_legs import ROW_MOVES, WhatRan, rows, run_in_parts

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.machine import JobState
from quadstep.machine import rebase as rebase_module
from quadstep.machine.move_items import MoveItems
from quadstep.machine.override import continue_plan, feeds_at, replan_scurve
from quadstep.machine.rebase import find, rebased
from quadstep.machine.remainder import move_item, rest_of
from quadstep.planner.plan import Plan, plan_program
from quadstep.planner.program import Program

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
CONFIG = ROUTER.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in ROUTER.axes)}
)


def parse(text: str) -> Program:
    return parse_gcode(text, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)


def test_a_plan_begun_again_where_a_part_began_goes_on_as_the_whole(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 100)
    whole = parse(rows(12))
    program = replace(whole, items=whole.items[:30])
    plan = plan_program(program, CONFIG)
    items = MoveItems(CONFIG, plan.start)
    for given in range(30, 180, 21):  # a part a row
        program = replace(program, items=whole.items[: given + 21])
        plan = continue_plan(program, plan, plan.scurve_states[0], feeds_at(100), "line", items)
    ticks = np.concatenate([[0], np.cumsum(plan.segments.numpy()["n"])])
    at = find(plan, ticks, len(plan) - 150)
    assert at is not None and at.index == at.segment >= 100
    assert at.moves in [s.move for s in plan.scurve_starts]
    again = rebased(plan, at)
    assert isinstance(again, Plan)
    assert list(again.segments.segments()) == list(plan.segments.segments(at.segment, None))
    assert again.start == tuple(s + m for s, m in zip(plan.start, at.motor))
    assert again.end == plan.end and again.moves == plan.moves - at.moves
    assert again.scurve_starts[0].move == 0  # where it begins: moving, from that part's state
    # the job keeps its program from there; more lines, and an override, plan what they would have
    rest = rest_of(program, move_item(program, CONFIG, plan.start, at.moves - 1) + 1)
    more = whole.items[len(program.items) : len(program.items) + 42]
    whole_job, kept_job = (
        replace(program, items=program.items + more),
        replace(rest, items=rest.items + more),
    )
    longer = continue_plan(whole_job, plan, plan.scurve_states[0], feeds_at(100), "line")
    shorter = continue_plan(kept_job, again, again.scurve_states[0], feeds_at(100), "line")
    assert list(shorter.segments.segments()) == list(longer.segments.segments(at.segment, None))
    assert shorter.end == longer.end
    for move in (1, again.scurve_starts[-1].move + 2, shorter.moves - 40):
        slow = replan_scurve(kept_job, shorter, move, feeds_at(10), feeds_at(100), "line")
        slow_whole = replan_scurve(
            whole_job, longer, move + at.moves, feeds_at(10), feeds_at(100), "line"
        )
        assert list(slow.segments.segments()) == list(
            slow_whole.segments.segments(at.segment, None)
        )


@pytest.mark.realtime
def test_a_long_jerk_limited_open_job_lets_go_of_what_ran_and_sends_the_same(
    start_emulator, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Given a row at a time, 4 rows ahead of the machine."""
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 60)
    ran = WhatRan(monkeypatch)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    whole = parse(rows(24))
    head = 1 + 5 * (ROW_MOVES + 1)
    run, longest = run_in_parts(emu.url, CONFIG, whole, head, ROW_MOVES + 1, 4 * ROW_MOVES)
    emu.stop()
    sent = ran.sent
    # it let go of what ran, several times
    assert ran.rebases >= 3, (ran.rebases, run.states.history)
    assert longest < len(sent)  # and kept less than that
    assert run.progress.done == run.progress.total == len(sent) + len(run.plan)
    sent.extend(run.plan.segments.segments())
    if JobState.STARVED not in run.states.history:
        assert_trace_is_prediction(trace, sent, axis_count=3)
