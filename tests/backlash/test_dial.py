"""The dial indicator's arithmetic: the steps before the one that moved the needle; the distance
less the reading; readings that cannot be a backlash, and results the moves explain (a preload that
never took the backlash up, a move back that never moved the carriage, a large jog) refused, naming
the value and the reason; the moves sized from the configured backlash and the travel."""

from __future__ import annotations

import pytest
from quadstep.backlash.dial import (
    MIN_MOVE_MM,
    DialError,
    DialPlan,
    from_jog_back,
    from_reading,
    plan,
)
from quadstep.config import AxisConfig, BacklashConfig


def test_jogging_back_counts_the_steps_before_the_needle_moved() -> None:
    assert from_jog_back(5, 400).steps == 4 and from_jog_back(5, 400).mm == 0.01
    assert from_jog_back(1, 80).steps == 0  # the first step moved it: no backlash to see
    with pytest.raises(DialError, match="steps until the needle moved = 0: must be at least 1"):
        from_jog_back(0, 400)


def test_a_reading_after_a_move_back_gives_the_distance_less_it() -> None:
    result = from_reading(0.5, -0.43, 400)  # the indicator's sign does not matter
    assert abs(result.mm - 0.07) < 1e-12 and abs(result.steps - 28) < 1e-9
    most = "reading = 0.6 mm: must be at most the distance moved, 0.5 mm"
    with pytest.raises(DialError, match=most):
        from_reading(0.5, 0.6, 400)
    with pytest.raises(DialError, match="distance = 0 mm: must be more than 0"):
        from_reading(0, 0, 400)


def test_results_the_moves_explain_are_refused_with_the_reason() -> None:
    move = DialPlan(1.0, 400)
    never = "reading = 0 mm after moving back 1 mm: the carriage never moved"
    with pytest.raises(DialError, match=never):
        from_reading(1.0, 0.0, 400, move)
    preload = "the result, 399.96 steps, is the preload \\(400 steps, 1 mm\\) within a step"
    with pytest.raises(DialError, match=preload):
        from_reading(1.0, 0.0001, 400, move)
    with pytest.raises(DialError, match="the result, 399 steps, is the preload"):
        from_jog_back(400, 400, move)
    assert from_jog_back(399, 400, move).steps == 398  # two steps short of it: a backlash
    with pytest.raises(DialError, match="the needle moved during a jog of 4 steps"):
        from_jog_back(100, 400, move, last_jog=4)


def test_the_moves_are_sized_from_the_configured_backlash_and_the_travel() -> None:
    axis = AxisConfig(
        name="Z",
        steps_per_mm=400,
        max_speed=10,
        max_accel=100,
        travel_min=-8,
        travel_max=0,
        backlash=BacklashConfig(mm=0.3),
    )
    assert plan(axis).move_mm == MIN_MOVE_MM == 1.0
    assert plan(axis.model_copy(update={"backlash": BacklashConfig(mm=0.7)})).move_mm == 1.4
    assert plan(axis, 0.75).move_steps == 300 and plan(axis, 0.75).jog_steps(0.01) == 4
    short = "Z: move = 1 mm: more than a quarter of its travel \\(0.75 mm\\)"
    with pytest.raises(DialError, match=short):
        plan(axis.model_copy(update={"travel_min": -3}))
