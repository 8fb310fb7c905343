"""The exact parts of the backlash figures (tests/bench/bench_backlash.py prints them for 20 values): every axis
measured within its bound by the probe and by the switch, and jobs whose take-ups keep the carriage on the
path, cost under 1 % of the time and stay within each axis's acceleration, as the stream's states and the
emulator's trace both show."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np

from backlash_helpers import STEPS_PER_MM, TICK_HZ, backlash_config, circle_gcode, pocket_gcode, pocket_path
from backlash_jobs import Ran, path_error, run_job, takeup_accel
from backlash_rig import HYSTERESIS, SWITCH_END, probe, rig, rig_config, switch
from quadstep.kernel.engine_model import predict
from quadstep.gcode import parse_gcode
from quadstep.machine.backlash import calibrate_switch
from quadstep.planner.plan import plan_program

SMOOTHING = TICK_HZ // 100  # the trace's second differences over 10 ms
QUANTUM = 2 / SMOOTHING**2 * TICK_HZ**2 / STEPS_PER_MM  # their error, mm/s²: each step within half a step


def test_the_probe_measures_every_axis_within_a_step(tmp_path: Path, emulator_binary: Path) -> None:
    rng = random.Random(3)
    for axis in range(3):  # X and Y at the block's corner, Z on its top tested along its −X face
        backlash = tuple(rng.uniform(0, 120) for _ in range(3))
        with rig(tmp_path, axis, backlash, binary=emulator_binary) as machine:
            result = probe(machine, axis, tries=2)
        assert result.accepted and result.spread_steps == 0
        assert abs(result.steps - backlash[axis]) < 1.0, (axis, result.steps, backlash)


def test_the_switch_with_bounce_is_within_its_rounding_and_its_calibrations_error(tmp_path: Path,
                                                                                 emulator_binary: Path) -> None:
    rng = random.Random(5)
    for axis in (0, 2):  # a min switch and a max one
        calibration = tuple(rng.uniform(0, 120) for _ in range(3))
        with rig(tmp_path, axis, calibration, binary=emulator_binary) as machine:
            known = probe(machine, axis, tries=1).mm
            hysteresis = calibrate_switch(machine, "XYZ"[axis], known, end=SWITCH_END[axis], tries=2, search=8)
        calibration_error = hysteresis * STEPS_PER_MM - HYSTERESIS[axis]
        assert abs(calibration_error) < 2.0  # the sum's rounding (< 1) and the probe's (< 1)
        backlash = tuple(rng.uniform(0, 120) for _ in range(3))
        config = rig_config(tuple(hysteresis if a == axis else 0.0 for a in range(3)))
        with rig(tmp_path, axis, backlash, config, binary=emulator_binary) as machine:
            result = switch(machine, axis, tries=3)
        assert result.accepted and result.spread_steps == 0  # the bounce does not move the first contact's latch
        assert abs(result.sum_steps - backlash[axis] - HYSTERESIS[axis]) < 1.0  # the sum, rounded once
        assert abs(result.steps - backlash[axis]) < 1.0 + abs(calibration_error)


def check_takeups(ran: Ran) -> None:
    """Every take-up within the axis's acceleration: exactly in the stream's states, and in the trace's own
    second differences up to their quantisation; the trace is the stream's steps, take-ups included."""
    assert ran.ended_by == "done"
    predicted = predict(ran.sent.segments.segments(), axis_count=3).steps
    assert np.array_equal(ran.rows[:, :3].astype(np.int64), predicted)
    accel = takeup_accel(ran, SMOOTHING)
    assert set(accel) == {0, 1}
    for axis, (exact, seen) in accel.items():
        limit = ran.config.axes[axis].max_accel
        assert 0.9 * limit < exact <= limit * (1 + 1e-9)
        assert seen <= limit + QUANTUM


def plain_ticks(gcode: str, mm: tuple[float, float, float]) -> int:
    config = backlash_config(mm, compensate=False)
    start = (0, 0, 0)
    return plan_program(parse_gcode(gcode, config.axis_names, start, config.arc_tolerance), config, start).duration_ticks


def test_a_pocket_keeps_the_carriage_on_its_path_in_no_more_time(tmp_path: Path, emulator_binary: Path) -> None:
    mm, gcode = (0.1, 0.15, 0.0), pocket_gcode(20, 6, 1.5, 15)
    lines = (3, len(gcode.splitlines()) - 1)  # the passes and stepovers, before the rapid home
    ran = run_job(tmp_path, "with", gcode, mm, True, binary=emulator_binary)
    check_takeups(ran)  # an axis stopping between quadratic segments keeps its state for the cubic window after
    assert {t.kind for t in ran.sent.compensated.takeups} <= {"gap", "rest"}
    assert path_error(ran, pocket_path(20, 6, 1.5), *lines) <= 1.0
    assert ran.sent.segments.ticks <= 1.01 * plain_ticks(gcode, mm)
    without = run_job(tmp_path, "without", gcode, mm, False, binary=emulator_binary)
    assert without.ended_by == "done" and without.sent.compensated.takeups == []
    assert 0.9 * 40 <= path_error(without, pocket_path(20, 6, 1.5), *lines) <= 1.1 * 40  # X's backlash


def test_a_circles_take_ups_stay_within_the_acceleration_in_no_more_time(tmp_path: Path,
                                                                         emulator_binary: Path) -> None:
    mm, gcode = (0.1, 0.1, 0.0), circle_gcode(20, 10)
    ran = run_job(tmp_path, "circle", gcode, mm, True, binary=emulator_binary)
    assert {"gap", "around"} <= {t.kind for t in ran.sent.compensated.takeups}
    check_takeups(ran)
    assert ran.sent.segments.ticks <= 1.01 * plain_ticks(gcode, mm)
