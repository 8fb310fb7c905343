"""Fine moves under S-curves: chains of moves a few steps long, at any step size, feed and jerk,
are planned (never refused) and land exactly, checked from the cubic segments the firmware runs.

A move no whole-tick S-curve lands runs at one constant speed per axis instead
(ScurvePlanner._steady); that path is forced here too, and held to the same checks.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scurve_checks import check_scurve_plan

from quadstep.config import MachineConfig, parse_config
from quadstep.kernel.engine_model import predict
from quadstep.planner.moves import MoveTable, build_moves
from quadstep.planner.plan import Plan, plan_moves
from quadstep.planner.program import LinearMove, Program
from quadstep.planner.scurve import ScurvePlanner
from quadstep.planner.scurve_chain import Phase, PhaseRun
from quadstep.planner.scurve_profile import Profile
from quadstep.planner.stream import Stream


def router(jerk: float) -> MachineConfig:
    specs = [("X", 40, 500, jerk), ("Y", 40, 500, jerk), ("Z", 15, 200, jerk / 2)]
    return parse_config(
        {
            "tick_hz": 32000,
            "junction_deviation": 0.01,
            "axes": [
                {
                    "name": n,
                    "steps_per_mm": 400,
                    "max_speed": v,
                    "max_accel": a,
                    "max_jerk": j,
                    "travel_min": -500,
                    "travel_max": 500,
                }
                for n, v, a, j in specs
            ],
        }
    )


def fine_line(
    step: float, feed: float, count: int, direction: tuple[float, float] = (1.0, 0.0)
) -> list:
    """`count` collinear moves of `step` mm each (along `direction`), at `feed` mm/min."""
    return [
        LinearMove(k, (k * step * direction[0], k * step * direction[1], 0.0), feed / 60)
        for k in range(1, count + 1)
    ]


def plan_exactly(items: list, config: MachineConfig) -> tuple[Plan, MoveTable]:
    """Plan the items; the plan lands every move and rests at its end, as the firmware runs it."""
    table = build_moves(Program(items=items, lines=len(items)), config, (0, 0, 0))
    plan = plan_moves(table, config)
    assert isinstance(plan.segments, Stream)
    assert check_scurve_plan(plan, table) == []
    model = predict(plan.segments.segments(), list(plan.start), axis_count=3)
    assert tuple(model.positions) == plan.end == table.target[-1]
    assert plan.max_landing_error <= 4096  # half a step, in 1/8192 step
    return plan, table


@pytest.mark.parametrize("jerk", [5000.0, 20000.0])
@pytest.mark.parametrize("feed", [100.0, 600.0, 2400.0])
@pytest.mark.parametrize("step", [0.001, 0.005, 0.0075, 0.01, 0.0125, 0.025, 0.03, 0.05])
def test_collinear_fine_moves_are_planned_exactly(step: float, feed: float, jerk: float) -> None:
    plan, table = plan_exactly(fine_line(step, feed, 256), router(jerk))
    assert len(table) + table.skipped_lines == 256 and len(table) >= 100


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.floats(0.001, 0.05),
    st.floats(30.0, 3000.0),
    st.floats(5000.0, 60000.0),
    st.floats(0.0, 2 * math.pi),
    st.integers(20, 120),
)
def test_fine_moves_at_any_step_feed_and_jerk_land_exactly(
    step: float, feed: float, jerk: float, angle: float, count: int
) -> None:
    plan_exactly(fine_line(step, feed, count, (math.cos(angle), math.sin(angle))), router(jerk))


def test_a_move_no_s_curve_lands_runs_at_a_steady_speed_exactly(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every other move refused by the S-curve: those run at a constant speed per axis, exactly."""
    shaped = ScurvePlanner._segments

    def every_other(
        self: ScurvePlanner, table: MoveTable, k: int, p: Profile
    ) -> tuple[list[Phase], PhaseRun] | None:
        return None if k % 2 else shaped(self, table, k, p)

    monkeypatch.setattr(ScurvePlanner, "_segments", every_other)
    steady = []
    monkeypatch.setattr(
        ScurvePlanner, "_steady", lambda self, *a: (steady.append(a[1]), _steady(self, *a))[1]
    )
    items = fine_line(0.0125, 600.0, 60, (0.6, 0.8)) + [
        LinearMove(61, (0.3, 0.0, -0.2), 20.0),
        LinearMove(62, (0.0, 0.0, 0.0), None),
    ]
    plan_exactly(items, router(20000.0))
    assert steady == list(range(1, 62, 2))


_steady = ScurvePlanner._steady
