"""Machine units (mm, mm/s, mm/s²) as the board's integers: steps, steps per tick, HOLD
decelerations."""

from __future__ import annotations

import math

from ..config import AxisConfig, MachineConfig

# HOLD decelerations: d / 2^DECEL_SHIFT step per tick², 1 … DECEL_MAX
from ..kernel.fixed import DECEL_MAX, DECEL_SHIFT


def hold_decel(axis: AxisConfig, tick_hz: int) -> int:
    """The axis's max_accel as a HOLD deceleration, rounded down so it never brakes harder than
    allowed.

    Below one unit (about 149 steps/s² at 50 kHz) the firmware's gentlest deceleration, 1, is used.
    """
    per_tick2 = axis.max_accel * axis.steps_per_mm / (tick_hz * tick_hz)
    return max(1, min(DECEL_MAX, math.floor(per_tick2 * (1 << DECEL_SHIFT))))


def hold_decels(config: MachineConfig) -> tuple[int, ...]:
    return tuple(hold_decel(axis, config.tick_hz) for axis in config.axes)


def braking_steps(speed: float, decel: int) -> float:
    """Steps to come to rest from `speed` (steps per tick) at a HOLD deceleration `decel`."""
    a = decel / (1 << DECEL_SHIFT)
    return speed * speed / (2.0 * a)


def step_limits(axis: AxisConfig) -> tuple[int, int]:
    """The travel as step positions (low, high): the outermost steps still inside travel_min …
    travel_max."""
    inner_min = math.ceil(axis.travel_min * axis.steps_per_mm - 1e-9)
    inner_max = math.floor(axis.travel_max * axis.steps_per_mm + 1e-9)
    if axis.invert:
        return -inner_max, -inner_min
    return inner_min, inner_max


def step_direction(axis: AxisConfig, direction: int) -> int:
    """The sign, in steps, of a jog in machine direction `direction` (+1: toward travel_max)."""
    return -direction if axis.invert else direction
