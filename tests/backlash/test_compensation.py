"""The compensation stage on its own (no board): every take-up makes exactly its steps, within the axis's
acceleration, where the plan leaves room for it; the plan's own steps are untouched; the band follows."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from backlash_helpers import backlash_config, circle_gcode, pocket_gcode, pushed_plus
from quadstep.backlash.band import Band, BandAxis
from quadstep.backlash.base import from_arrays, from_items
from quadstep.backlash.compensate import compensate
from quadstep.backlash.takeup import design
from quadstep.config import MachineConfig
from quadstep.kernel.engine_model import predict
from quadstep.gcode import parse_gcode
from quadstep.planner.plan import Plan, plan_program
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.fixed import SIGMA


def plan_of(gcode: str, config: MachineConfig) -> Plan:
    start = (0,) * len(config.axes)
    return plan_program(parse_gcode(gcode, config.axis_names, start, config.arc_tolerance), config, start)


def motor_by_tick(steps: np.ndarray, axis: int, ticks: int) -> np.ndarray:
    """An axis's step count after every tick 0 … ticks."""
    mine = steps[steps[:, 1] == axis]
    delta = np.zeros(ticks + 1, dtype=np.int64)
    np.add.at(delta, mine[:, 0], mine[:, 2])
    return np.cumsum(delta)


def band(config: MachineConfig, sides: tuple[int, ...]) -> Band:
    """Each axis's carriage pushed to `sides` (+1 / −1)."""
    return Band(tuple(replace(a, w=a.size if s > 0 else 0, base=-a.size if s > 0 else 0)
                      for a, s in zip(Band.of(config).axes, sides)))


def test_every_take_up_makes_its_steps_and_every_other_step_is_the_plans() -> None:
    config = backlash_config((0.1, 0.07, 0.0))
    plan = plan_of(circle_gcode(20, 10), config)
    # X last pushed −, Y +: the circle's first motion needs no take-up, every reversal after it does
    comp = compensate(from_arrays(plan.segments), config, band(config, (-1, 1, 1)))
    assert [(t.axis, t.steps) for t in comp.takeups] == [(0, 40), (1, -28), (0, -40), (1, 28), (0, 40)]
    assert comp.added_ticks == 1  # the stream's first tick puts every axis on its ideal: nothing inserted
    base = predict(plan.segments.segments(), axis_count=3)
    made = predict(comp.stream.segments(), axis_count=3)
    ticks = made.motion_ticks
    assert ticks == base.motion_ticks + 1
    for axis in range(3):
        planned = np.concatenate([[0], motor_by_tick(base.steps, axis, base.motion_ticks)])  # one tick later
        motor = motor_by_tick(made.steps, axis, ticks)
        takeup = np.zeros(ticks + 1)
        for t in (t for t in comp.takeups if t.axis == axis):
            ramp = design(t.steps, *_limits(config, axis, t.peak_accel))
            assert ramp.ticks == t.ticks
            progress = np.array([float(ramp.state(k)[0]) / SIGMA for k in range(ramp.ticks + 1)])
            takeup[t.start: t.start + ramp.ticks + 1] += progress
            takeup[t.start + ramp.ticks + 1:] += t.steps
        # the motor is the plan plus the ramp, rounded once: within a step of it at every tick
        assert np.max(np.abs(motor - planned - takeup)) <= 1.0
        assert motor[-1] == planned[-1] + sum(t.steps for t in comp.takeups if t.axis == axis)
    # the plan's segments outside the take-ups go out as they are, in order
    refs = [r for r in comp.stream.ref if r >= 0]
    assert refs == sorted(refs) and len(refs) > 0.9 * len(plan)
    assert sum(isinstance(s, CubicSegment) for s in comp.stream.segments()) == len(comp.stream) - len(refs) - 1


def _limits(config: MachineConfig, axis: int, peak_mm: float) -> tuple[float, float]:
    """The acceleration and jerk the stage designed the ramp with (its peak is within a part in 10^3 of it)."""
    a = config.axes[axis]
    accel = a.max_accel * a.steps_per_mm / config.tick_hz**2
    jerk = accel / 0.005 / config.tick_hz
    used = peak_mm * a.steps_per_mm / config.tick_hz**2
    return (accel if used > 0.999 * accel else used * (1 + 1e-12)), jerk


def test_take_ups_stay_within_the_axis_acceleration_left_by_the_plan() -> None:
    config = backlash_config((0.3, 0.3, 0.0))
    plan = plan_of(circle_gcode(10, 30) + pocket_gcode(10, 4, 1, 20), config)
    comp = compensate(from_arrays(plan.segments), config, pushed_plus(config))
    assert len(comp.takeups) > 10
    timeline = np.concatenate([[0], np.cumsum(plan.segments.numpy()["n"].astype(np.int64))])
    arrays = plan.segments.numpy()
    for t in comp.takeups:
        assert t.peak_accel <= 500 * (1 + 1e-9)
        if t.kind in ("around", "after"):  # superposed: the plan's own acceleration there plus the ramp's
            lo, hi = np.searchsorted(timeline, [t.planned, t.planned + t.ticks], side="right") - 1
            v0 = arrays["v0"][lo:hi + 1, t.axis].astype(float)
            vn = arrays["vn"][lo:hi + 1, t.axis].astype(float)
            plan_accel = np.max(np.abs(vn - v0) / 4096 / arrays["n"][lo:hi + 1]) * 32_000**2 / 400
            assert plan_accel + t.peak_accel <= 500 * (1 + 1e-6)


def test_a_pockets_take_ups_fit_in_its_stepovers_and_cost_no_time() -> None:
    config = backlash_config((0.2, 0.2, 0.0))
    plan = plan_of(pocket_gcode(20, 6, 1.5, 15), config)
    comp = compensate(from_arrays(plan.segments), config, band(config, (1, 1, 1)))
    x = [t for t in comp.takeups if t.axis == 0]
    assert len(x) >= 4 and {t.kind for t in x[:-1]} == {"gap"}  # the last one: the rapid home, from a stop
    assert comp.stream.ticks <= plan.duration_ticks * 1.01


def test_the_band_follows_a_stop_inside_a_take_up() -> None:
    config = backlash_config((0.1, 0.0, 0.0))
    plan = plan_of("G1 X5 F600\nG1 X0\n", config)
    comp = compensate(from_arrays(plan.segments), config, band(config, (1, 1, 1)))
    (takeup,) = comp.takeups
    assert takeup.kind == "rest" and takeup.steps == -40
    made = predict(comp.stream.segments(), axis_count=3)
    motor = motor_by_tick(made.steps, 0, made.motion_ticks)
    middle = takeup.start + takeup.ticks // 2
    inside = comp.band_at(middle).axes[0]
    assert 0 < inside.w < 40 and inside.offset() - BandAxis(40, 40, -40).offset() == motor[middle] - motor[takeup.start]
    assert comp.band_at(middle, moved=(int(motor[middle]) - 3, 0, 0)).axes[0].w == inside.w - 3  # the hold went on
    assert comp.band_at(made.motion_ticks).axes[0].w == 0 and comp.band_end.axes[0].w == 0


def test_an_axis_seen_first_takes_no_take_up_and_knows_its_side_after() -> None:
    config = backlash_config((0.1, 0.0, 0.0))
    plan = plan_of("G1 X-5 F600\n", config)
    comp = compensate(from_arrays(plan.segments), config, Band.of(config))
    assert comp.takeups == [] and comp.band_end.axes[0].w == 0 and comp.band_end.axes[0].offset() == 0


def test_mixed_streams_read_back_like_the_arrays() -> None:
    config = backlash_config((0.1, 0.1, 0.0))
    plan = plan_of(circle_gcode(5, 10), config)
    arrays, items = from_arrays(plan.segments), from_items(list(plan.segments.segments()), 3)
    assert np.array_equal(arrays.steps, items.steps) and np.array_equal(arrays.rest_before, items.rest_before)
    for k in (0, 17, len(plan) - 1):
        assert arrays.chain_before(k).axes == items.chain_before(k).axes
