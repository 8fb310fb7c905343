"""A zigzag whose X reverses sharply at every tip: a take-up of one step runs inside the reversal (no stop, no
added time, the carriage at most that step behind the plan while it runs); a larger one stops there and runs at
rest (no lag). On the emulator with a simulated machine whose backlash only the simulation knows."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from backlash_helpers import STEPS_PER_MM, backlash_config, pushed_plus, zigzag_gcode, zigzag_path
from backlash_jobs import path_error, plan_lag, run_job
from quadstep.backlash.base import from_arrays
from quadstep.backlash.compensate import compensate
from quadstep.kernel.engine_model import predict
from quadstep.gcode import parse_gcode
from quadstep.planner.plan import plan_program

PASSES, LENGTH, STEP, FEED = 4, 10.0, 0.5, 20.0
GCODE = zigzag_gcode(PASSES, LENGTH, STEP, FEED)


def test_a_one_step_take_up_runs_inside_each_tip_and_costs_no_time() -> None:
    config = backlash_config((1 / STEPS_PER_MM, 0.0, 0.0))
    plan = plan_program(parse_gcode(GCODE, config.axis_names, (0, 0, 0), config.arc_tolerance), config, (0, 0, 0))
    comp = compensate(from_arrays(plan.segments), config, pushed_plus(config))
    assert [(t.axis, t.steps, t.kind) for t in comp.takeups] == [(0, -1, "around"), (0, 1, "around"),
                                                                (0, -1, "around")]
    assert comp.stream.ticks == plan.duration_ticks + 1  # the anchor tick alone


def test_a_larger_take_up_still_stops_at_the_tip() -> None:
    config = backlash_config((0.05, 0.0, 0.0))
    plan = plan_program(parse_gcode(GCODE, config.axis_names, (0, 0, 0), config.arc_tolerance), config, (0, 0, 0))
    comp = compensate(from_arrays(plan.segments), config, pushed_plus(config))
    assert {t.kind for t in comp.takeups} == {"rest"} and len(comp.takeups) == PASSES - 1


def test_on_the_emulator_the_carriage_ends_where_planned_and_lags_at_most_the_take_up(tmp_path: Path,
                                                                                    emulator_binary: Path) -> None:
    plain = run_job(tmp_path, "plain", GCODE, (0.0, 0.0, 0.0), True, binary=emulator_binary)
    for mm, lag in ((1 / STEPS_PER_MM, 1.0), (0.05, 0.0)):
        ran = run_job(tmp_path, f"b{mm}", GCODE, (mm, 0.0, 0.0), True, binary=emulator_binary)
        assert ran.ended_by == "done"
        assert np.array_equal(ran.rows[:, :3].astype(np.int64),
                              predict(ran.sent.segments.segments(), axis_count=3).steps)  # trace = prediction
        assert plan_lag(ran) <= lag + 1e-9, mm
        # the carriage within the steppers' own distance from the path (each axis within half a step) plus its
        # lag, and ends where planned
        corners = zigzag_path(PASSES, LENGTH, STEP)
        lines = (3, PASSES + 2)
        assert path_error(ran, corners, *lines) <= np.hypot(0.5, 0.5) + lag
        carriage_x = ran.rows[ran.rows[:, 1] == 0, 4][-1] + ran.backlash_steps[0] / 2
        assert carriage_x == 0.0
        if lag:  # inside the tips: the anchor tick alone added
            assert ran.sent.segments.ticks == plain.sent.segments.ticks + 1
