"""The jerk-limited planner over random jobs, checked from the cubic segments the firmware would execute.

Every move lands exactly on its step target with the acceleration back at 0; the job rests at its pauses
and its end; speeds, accelerations and jerks stay within the limits and their quantisation; the firmware's
own checks pass on every segment; a move alone takes no less time than Ruckig's time-optimal profile under
the same limits (it cannot be faster without breaking one) and at most a few per cent more; the look-ahead's
reach is the distance of the jerk-limited ramp, not √(2aL); and the configuration refuses a jerk the cubic
segment cannot carry.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import pytest
from hypothesis import example, HealthCheck, assume, given, settings
from hypothesis import strategies as st
from ruckig import InputParameter, Result, Ruckig, Trajectory
from scurve_checks import check_scurve_plan

from quadstep.config import ConfigError, MachineConfig, parse_config
from quadstep.kernel.engine_model import predict
from quadstep.planner.jerk import ramp_distance, reachable_speed
from quadstep.planner.moves import MoveTable, build_moves
from quadstep.planner.plan import Plan, plan_moves
from quadstep.planner.program import Dwell, Item, LinearMove, Pause, Program
from quadstep.planner.stream import Stream


def jerk_config(fast: bool) -> MachineConfig:
    """The router with S-curves, or four axes at 3/4 step per tick with very different scales and limits."""
    if not fast:
        specs = [("X", 400, 40, 500, 20000), ("Y", 400, 40, 500, 20000), ("Z", 400, 15, 200, 5000)]
        hz = 32000
    else:
        hz = 40000
        specs = [("X", 80, 0.75 * hz / 80, 30000, 3e6), ("Y", 400, 0.75 * hz / 400, 2000, 2e5),
                 ("Z", 1600, 0.75 * hz / 1600, 500, 2e4), ("A", 5, 0.75 * hz / 5, 100, 5e5)]
    return parse_config({
        "tick_hz": hz,
        "junction_deviation": 0.05 if fast else 0.01,
        "axes": [{"name": n, "steps_per_mm": s, "max_speed": v, "max_accel": a, "max_jerk": j,
                  "travel_min": -500, "travel_max": 500} for n, s, v, a, j in specs],
    })


ROUTER = jerk_config(False)
FAST = jerk_config(True)


@st.composite
def jobs(draw: st.DrawFn, config: MachineConfig) -> list[Item]:
    """Random moves: long and tiny, fast and slow, some axes still, chains of short chords, a few stops."""
    count = len(config.axes)
    scale = draw(st.sampled_from([0.01, 0.3, 2.0, 20.0, 120.0]))
    position = [0.0] * count
    items: list[Item] = []
    for line in range(1, draw(st.integers(1, 20)) + 1):
        target = list(position)
        for i, axis in enumerate(config.axes):
            if draw(st.booleans()):
                step = draw(st.floats(-scale, scale, allow_nan=False))
                target[i] = min(axis.travel_max, max(axis.travel_min, position[i] + step))
        feed = draw(st.one_of(st.none(), st.floats(2.0, 400.0)))
        items.append(LinearMove(line, tuple(target), feed))
        stop = draw(st.integers(0, 20))
        if stop == 0:
            items.append(Dwell(line, draw(st.floats(0.0, 0.02))))
        elif stop == 1:
            items.append(Pause(line))
        position = target
    return items


def plan_items(items: Sequence[Item], config: MachineConfig) -> tuple[Plan, MoveTable]:
    table = build_moves(Program(items=list(items), lines=len(items)), config, (0,) * len(config.axes))
    return plan_moves(table, config), table


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
@pytest.mark.parametrize("config", [ROUTER, FAST], ids=["router", "fast"])
def test_random_scurve_jobs_are_exact_and_within_limits(config: MachineConfig, data: st.DataObject) -> None:
    plan, table = plan_items(data.draw(jobs(config)), config)
    assert isinstance(plan.segments, Stream)
    assert check_scurve_plan(plan, table) == []
    model = predict(plan.segments.segments(), list(plan.start), axis_count=len(config.axes))
    assert tuple(model.positions) == plan.end == (table.target[-1] if len(table) else plan.start)


def ruckig_ticks(length: float, vmax: float, accel: float, jerk: float) -> float:
    """Ruckig's time-optimal rest-to-rest duration along a path, in ticks (limits per tick)."""
    otg, out, inp = Ruckig(1), Trajectory(1), InputParameter(1)
    scale = 1e3  # ticks as milliticks keep Ruckig's numbers near 1
    inp.current_position, inp.target_position = [0.0], [length]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [vmax * scale], [accel * scale**2], [jerk * scale**3]
    assert otg.calculate(inp, out) == Result.Working
    return out.duration * scale


@settings(max_examples=80, deadline=None)
@given(st.floats(0.05, 250.0), st.sampled_from([2.0, 10.0, 40.0]), st.floats(-1.0, 1.0))
@example(41.0, 40.0, 6.103515625e-05)  # Y one step in 16,400: it waits at rest for its last ramp
def test_a_move_alone_takes_ruckigs_time_optimal_duration(length: float, feed: float, y: float) -> None:
    """Rest to rest our profile is the time-optimal one (Ruckig's) in whole ticks: never shorter (it would
    break a limit), and longer only by the rounding of its phases and the 0.5 % planning margin."""
    target = (length, y * length / 2, 0.0)
    plan, table = plan_items([LinearMove(1, target, feed)], ROUTER)
    assert check_scurve_plan(plan, table) == []
    optimal = ruckig_ticks(table.length[0], table.max_speed[0], table.accel[0], table.jerk[0])
    ticks = plan.duration_ticks - 1  # the anchor tick
    assert optimal * 0.999 <= ticks <= optimal * 1.02 + 8


@given(st.floats(0.0, 2e-3), st.floats(1e-4, 200.0), st.floats(1e-8, 1e-5), st.floats(1e-13, 1e-8))
def test_look_ahead_reach_is_the_jerk_limited_ramps(v: float, length: float, accel: float, jerk: float) -> None:
    top = reachable_speed(v, length, accel, jerk)
    assume(top - v > 1e-9 * v)  # a change the float can hold
    assert ramp_distance(v, top, accel, jerk) == pytest.approx(length, rel=1e-6)
    assert top <= math.sqrt(v * v + 2 * accel * length) * (1 + 1e-9)  # never more than constant acceleration


def test_a_jerk_the_cubic_segment_cannot_carry_is_refused() -> None:
    axis = {"name": "X", "steps_per_mm": 400, "max_speed": 40, "max_accel": 500, "travel_min": 0,
            "travel_max": 100}
    parse_config({"tick_hz": 32000, "axes": [dict(axis, max_jerk=1.2e6)]})
    with pytest.raises(ConfigError) as refused:
        parse_config({"tick_hz": 32000, "axes": [dict(axis, max_jerk=1.3e6)]})
    assert "axes[0].max_jerk = 1.3e+06: must be at most 1.24996e+06 mm/s³" in str(refused.value)
    with pytest.raises(ConfigError) as refused:  # so coarse that rounding it once per ramp errs by over 1 %
        parse_config({"tick_hz": 32000, "axes": [dict(axis, max_jerk=2000)]})
    assert "axes[0].max_jerk = 2000: must be at least 2441 mm/s³ (64 jerk quanta" in str(refused.value)
