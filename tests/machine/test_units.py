"""Machine units as board integers: HOLD decelerations, soft limits in steps, release timing."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from quadstep.config import MachineConfig, parse_config
from quadstep.jog import JogSettings, ReleaseDetector
from quadstep.machine.units import DECEL_MAX, braking_steps, hold_decel, hold_decels, step_direction, step_limits


def axis_config(**changes: object) -> MachineConfig:
    axis = {"name": "X", "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 40}
    axis.update(changes)
    return parse_config({"tick_hz": 50000, "axes": [axis]})


def test_hold_decel_is_max_accel_in_2_to_the_minus_24_step_per_tick_squared(machine: MachineConfig) -> None:
    # X: 500 mm/s² × 80 steps/mm = 40,000 steps/s² = 1.6e-5 step/tick² at 50 kHz = 268.4 units → 268
    # Z: 200 × 400 = 80,000 steps/s² = 3.2e-5 step/tick² = 536.9 units → 536
    assert hold_decels(machine) == (268, 268, 536)


def test_hold_decel_never_brakes_harder_than_max_accel_and_stays_in_the_protocol_range() -> None:
    hard = axis_config(steps_per_mm=1000, max_speed=30, max_accel=100_000).axes[0]
    assert hold_decel(hard, 50000) == DECEL_MAX
    gentle = axis_config(max_accel=50000**2 / 2**24 / 80).axes[0]  # the least max_accel allowed
    assert hold_decel(gentle, 50000) == 1
    with pytest.raises(ValueError, match="a hold's gentlest deceleration"):
        axis_config(max_accel=0.001)
    for accel in (10.0, 77.7, 500.0, 3000.0):
        axis = axis_config(max_accel=accel).axes[0]
        units = hold_decel(axis, 50000)
        assert units / 2**24 <= accel * 80 / 50000**2 < (units + 1) / 2**24


def test_braking_distance_is_v_squared_over_2a() -> None:
    # 0.08 step/tick (4,000 steps/s = 50 mm/s at 80 steps/mm) at 268 units: 0.0064 / (2 × 1.5974e-5) = 200.3 steps
    assert braking_steps(0.08, 268) == pytest.approx(0.0064 / (2 * 268 / 2**24))


def test_step_limits_are_the_outermost_steps_inside_the_travel() -> None:
    assert step_limits(axis_config().axes[0]) == (0, 3200)
    assert step_limits(axis_config(travel_min=0.006, travel_max=39.994).axes[0]) == (1, 3199)
    inverted = axis_config(invert=True).axes[0]
    assert step_limits(inverted) == (-3200, 0)
    assert step_direction(inverted, 1) == -1
    assert step_direction(axis_config().axes[0], -1) == -1


def test_release_needs_the_first_repeat_within_the_first_timeout_then_each_within_the_repeat_timeout() -> None:
    now = [100.0]
    release = ReleaseDetector(0.5, 0.1, clock=lambda: now[0])
    release.press()
    assert release.deadline() == pytest.approx(100.5)
    now[0] = 100.45  # still inside the terminal's initial repeat delay
    assert not release.released()
    release.press()  # first repeat: the deadline never moves back
    assert release.deadline() == pytest.approx(100.55)
    now[0] = 100.5
    release.press()
    assert release.deadline() == pytest.approx(100.6)
    now[0] = 100.59
    assert not release.released()
    now[0] = 100.6
    assert release.released()
    assert release.presses == 3


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"step_presets": (0.1, 0.0)}, "step_presets[1] = 0.0: must be greater than 0 and at most 1000 mm"),
        ({"speed_presets": (0.5, 1.5)}, "speed_presets[1] = 1.5: must be greater than 0 and at most 1 (the axis max)"),
        ({"first_repeat_timeout": 0.1, "repeat_timeout": 0.2},
         "repeat_timeout = 0.2: must be at most first_repeat_timeout = 0.1"),
    ],
)
def test_bad_jog_settings_name_the_field_and_the_limit(changes: dict[str, object], message: str) -> None:
    with pytest.raises(ValidationError) as info:
        JogSettings(**changes)  # type: ignore[arg-type]
    assert message in str(info.value)


def test_repeat_timeout_must_be_positive() -> None:
    with pytest.raises(ValidationError) as info:
        JogSettings(repeat_timeout=0)
    assert info.value.errors()[0]["loc"] == ("repeat_timeout",)
