"""Planner properties over random jobs, checked from the segments the firmware would execute.

Limits (per-axis speed and acceleration, within 1/4096 step/tick quantisation), speed
continuity inside moves, the cornering rule at junctions, stopping distance, exact
landing on every move's step target, the residual chain, and planned duration no
longer than planning every move alone from rest to rest.
"""

from __future__ import annotations

import random
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from planner_checks import check_plan, feed_problems

from quadstep.config import MachineConfig, load_config, parse_config
from quadstep.kernel.engine_model import advance, predict, residual
from quadstep.planner.lookahead import PLAN_ACCEL_FRACTION
from quadstep.planner.moves import MoveTable, build_moves
from quadstep.planner.plan import Plan, plan_moves
from quadstep.planner.profile import fit_profiles
from quadstep.planner.program import Dwell, Item, JobError, LinearMove, Pause, Program
from quadstep.kernel.fixed import D

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")


def fast_config(axes: int = 3) -> MachineConfig:
    """Every axis at 3/4 step per tick (the planner's ceiling) with different scales and limits."""
    specs = [("X", 80, 30000), ("Y", 400, 2000), ("Z", 1600, 500), ("A", 5, 100)][:axes]
    return parse_config({
        "tick_hz": 40000,
        "junction_deviation": 0.05,
        "axes": [
            {"name": n, "steps_per_mm": s, "max_speed": 0.75 * 40000 / s, "max_accel": a,
             "travel_min": -500, "travel_max": 500}
            for n, s, a in specs
        ],
    })


FAST = fast_config()


def plan_items(items: Sequence[Item], config: MachineConfig,
               start: tuple[int, ...] | None = None) -> tuple[Plan, MoveTable]:
    table = build_moves(Program(items=list(items), lines=len(items)), config, start or (0,) * len(config.axes))
    return plan_moves(table, config), table


@st.composite
def jobs(draw: st.DrawFn, config: MachineConfig) -> list[LinearMove | Dwell | Pause]:
    """Random moves inside the travel: long and tiny, fast and slow, some axes still, a few stops."""
    count = len(config.axes)
    scale = draw(st.sampled_from([0.003, 0.05, 1.0, 10.0, 60.0]))
    position = [0.0] * count
    items: list[LinearMove | Dwell | Pause] = []
    for line in range(1, draw(st.integers(1, 25)) + 1):
        target = list(position)
        for i, axis in enumerate(config.axes):
            if draw(st.booleans()):
                step = draw(st.floats(-scale, scale, allow_nan=False))
                target[i] = min(axis.travel_max, max(axis.travel_min, position[i] + step))
        feed = draw(st.one_of(st.none(), st.floats(2.0, 400.0)))
        accel = draw(st.one_of(st.none(), st.none(), st.floats(5.0, 5000.0)))
        items.append(LinearMove(line, tuple(target), feed, accel))
        stop = draw(st.integers(0, 30))
        if stop == 0:
            items.append(Dwell(line, draw(st.floats(0.0, 0.03))))
        elif stop == 1:
            items.append(Pause(line))
        position = target
    return items


def reference_ticks(plan: Plan, table: MoveTable) -> int:
    """Each move planned alone from rest to rest with the same limits, plus the dwells."""
    total = 0
    for k in range(len(table)):
        accel = table.accel[k]
        total += next(fit_profiles(table.length[k], 0.0, 0.0, table.max_speed[k], accel,
                                   accel * PLAN_ACCEL_FRACTION)).duration
    a = plan.segments.numpy()
    return total + int(a["n"][a["axes"] == 0].sum())


def assert_good(plan: Plan, table: MoveTable, items: list[LinearMove | Dwell | Pause]) -> None:
    """Every check passes (moves have one line each, so feeds are found by line)."""
    feed = {item.line: item.feed for item in items if isinstance(item, LinearMove)}
    problems = check_plan(plan, table)
    problems += feed_problems(plan, table, [feed[line] for line in table.line])
    assert problems == []
    assert plan.duration_ticks <= reference_ticks(plan, table)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_random_jobs_on_the_router(data: st.DataObject) -> None:
    items = data.draw(jobs(ROUTER))
    plan, table = plan_items(items, ROUTER)
    assert_good(plan, table, items)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data(), st.integers(1, 4))
def test_random_jobs_at_the_speed_ceiling(data: st.DataObject, axes: int) -> None:
    config = fast_config(axes)
    items = data.draw(jobs(config))
    start = tuple(data.draw(st.integers(-1000, 1000)) for _ in range(axes))
    plan, table = plan_items(items, config, start)
    assert_good(plan, table, items)


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_the_engine_model_lands_where_the_plan_says(data: st.DataObject) -> None:
    """The firmware's step model (closed form), run over every step, ends on the last target."""
    items = data.draw(jobs(ROUTER))
    plan, table = plan_items(items, ROUTER)
    predicted = predict(plan.segments.segments(), list(plan.start), axis_count=3)
    assert tuple(predicted.positions) == plan.end
    if len(table):
        assert plan.end == table.target[-1]
    assert predicted.motion_ticks == plan.duration_ticks


@pytest.mark.slow
def test_ten_thousand_random_moves_land_exactly() -> None:
    rnd = random.Random(7)
    items: list[LinearMove | Dwell | Pause] = []
    point = [150.0, 100.0, -30.0]
    for line in range(1, 12001):
        scale = rnd.choice([0.002, 0.02, 0.5, 5.0, 50.0])
        point = [
            min(a.travel_max, max(a.travel_min, x + rnd.uniform(-scale, scale) * rnd.choice([0, 1, 1])))
            for a, x in zip(ROUTER.axes, point)
        ]
        items.append(LinearMove(line, tuple(point), rnd.choice([None, rnd.uniform(1, 60)])))
    plan, table = plan_items(items, ROUTER)
    assert len(table) > 10000
    # the firmware model's own chain: every residual as engine_model derives it, then advance()
    ideal2 = [2 * D * p for p in plan.start]
    position = list(plan.start)
    ends = set(plan.move_ends.tolist())
    landed = []
    for index, segment in enumerate(plan.segments.segments(), start=1):
        for mv in segment.axes:
            assert mv.r == residual(ideal2[mv.axis], position[mv.axis], mv.direction)
            ideal2[mv.axis], position[mv.axis] = advance(ideal2[mv.axis], position[mv.axis], segment.n, mv)
        if index in ends:
            landed.append(tuple(position))
    assert landed == table.target
    assert plan.end == ROUTER.to_steps(tuple(point)) == tuple(position)


# --- look-ahead and cornering ----------------------------------------------------------


def path_speed_at(plan: Plan, segment: int, start: bool = True) -> float:
    a = plan.segments.numpy()
    v = a["v0" if start else "vn"][segment].astype(float)
    mm = [x / 4096 * plan.config.tick_hz / axis.steps_per_mm for x, axis in zip(v, plan.config.axes)]
    return float(np.hypot.reduce(mm))


def test_corners_slow_exactly_to_the_junction_rule() -> None:
    """A square with long sides: each corner is taken at the junction-deviation speed, no slower."""
    square = [(100.0, 0.0), (100.0, 100.0), (0.0, 100.0), (0.0, 0.0)]
    items = [LinearMove(i + 1, (x, y, 0.0), 40.0) for i, (x, y) in enumerate(square)]
    plan, table = plan_items(items, ROUTER)
    # 90° corner: sin(θ/2) = √½, junction acceleration 500·√2 (both axes share the turn)
    sin_half = np.sqrt(0.5)
    expected = np.sqrt(500 * np.sqrt(2) * 0.01 * sin_half / (1 - sin_half))
    quantum = ROUTER.tick_hz / 4096 / 400  # mm/s of one speed unit
    for end in plan.move_ends[:-1]:
        assert path_speed_at(plan, end) == pytest.approx(expected, abs=quantum)
        assert path_speed_at(plan, end - 1, start=False) == pytest.approx(expected, abs=quantum)
    assert check_plan(plan, table) == []


def test_straight_moves_in_pieces_do_not_slow_down() -> None:
    """A line in ten pieces runs like one move: full speed through the joins, same duration."""
    whole, _ = plan_items([LinearMove(1, (100.0, 50.0, 0.0), 30.0)], ROUTER)
    pieces, table = plan_items([LinearMove(i, (10.0 * i, 5.0 * i, 0.0), 30.0) for i in range(1, 11)], ROUTER)
    for end in pieces.move_ends[:-1]:
        assert path_speed_at(pieces, end) == pytest.approx(30.0, rel=1e-3)
    assert abs(pieces.duration_ticks - whole.duration_ticks) <= 2 * len(table)
    assert check_plan(pieces, table) == []


def test_reversal_stops_and_dwell_is_exact() -> None:
    items: list[Item] = [LinearMove(1, (10.0, 0.0, 0.0), 30.0), Dwell(2, 0.1), LinearMove(3, (0.0, 0.0, 0.0), 30.0),
             LinearMove(4, (10.0, 0.0, 0.0), 30.0)]
    plan, table = plan_items(items, ROUTER)
    a = plan.segments.numpy()
    still = a["axes"] == 0
    assert int(a["n"][still].sum()) == round(0.1 * ROUTER.tick_hz)
    first_dwell = int(np.argmax(still))
    assert np.all(a["vn"][first_dwell - 1] == 0)
    assert path_speed_at(plan, plan.move_ends[1]) == 0.0  # full reversal: the junction speed is 0
    assert check_plan(plan, table) == []


def test_pause_comes_to_rest_and_is_marked() -> None:
    items: list[Item] = [LinearMove(1, (10.0, 0.0, 0.0), 30.0), Pause(2), LinearMove(3, (20.0, 0.0, 0.0), 30.0)]
    plan, table = plan_items(items, ROUTER)
    assert plan.pauses == [(plan.move_ends[0], 2)]
    assert np.all(plan.segments.numpy()["vn"][plan.move_ends[0] - 1] == 0)
    assert check_plan(plan, table) == []


def test_speed_reaches_the_feed_on_a_long_move() -> None:
    plan, _ = plan_items([LinearMove(1, (200.0, 0.0, 0.0), 25.0)], ROUTER)
    top = max(path_speed_at(plan, s) for s in range(len(plan)))
    quantum = ROUTER.tick_hz / 4096 / 400
    assert 25.0 - quantum <= top <= 25.0 + quantum


# --- whole-tick profiles -------------------------------------------------------------------


@pytest.mark.parametrize("u_in,u_out", [(0.0, 0.0), (0.0005, 0.0), (0.0002, 0.0007), (0.0008, 0.0008)])
def test_profiles_cover_the_distance_within_the_limits(u_in: float, u_out: float) -> None:
    length, u_max, accel = 3.0, 0.0008, 2e-7
    best = next(fit_profiles(length, u_in, u_out, u_max, accel, accel * PLAN_ACCEL_FRACTION))
    speeds = np.array(best.speeds)
    ticks = np.array(best.ticks)
    assert speeds[0] == u_in and speeds[-1] == u_out
    assert np.all(speeds <= u_max * (1 + 1e-12))
    assert np.all(np.abs(np.diff(speeds)) <= accel * ticks * (1 + 1e-9))
    assert np.all(ticks <= 1022)
    assert float(np.sum(ticks * (speeds[:-1] + speeds[1:]) / 2)) == pytest.approx(length, abs=1e-9)
    assert best.distance_error == pytest.approx(0.0, abs=1e-9)


# --- what the planner refuses -------------------------------------------------------------


def test_a_target_outside_the_travel_names_line_and_axis() -> None:
    items = [LinearMove(3, (10.0, 10.0, 0.0), 30.0), LinearMove(7, (10.0, 210.0, 0.0), 30.0)]
    with pytest.raises(JobError, match=r"^line 7: Y 210\.000 mm is outside the travel 0\.000 … 200\.000 mm$"):
        plan_items(items, ROUTER)


def test_segments_are_compact() -> None:
    plan, _ = plan_items([LinearMove(1, (50.0, 20.0, -5.0), 30.0)], ROUTER)
    # n (2) + axis byte (1) + 3 axes × (v0, vn, r) (18) + source line (4)
    assert plan.segments.nbytes() == 25 * len(plan)
