"""The machine configuration's [inputs] as the firmware's CONFIG, and which input is an axis's
switch."""

from __future__ import annotations

import math

from ..config import MachineConfig
from ..kernel.fixed import MAX_AXES
from ..protocol import Config, Input
from ..protocol.constants import INPUT_COUNT
from ..protocol.wire import four_axes
from .units import hold_decels


def input_mask(names: tuple[str, ...]) -> int:
    return sum(1 << Input[name.upper()] for name in names)


def config_message(config: MachineConfig, axis_count: int) -> Config:
    """CONFIG for the firmware (axis_count axes): polarity, enabled inputs, hard limits, debounce in
    ticks, and the feed hold button's decelerations (each axis's max_accel, as the user's stop)."""
    inputs = config.inputs
    ticks = min(255, math.ceil(inputs.debounce_ms * config.tick_hz / 1000))
    decels = list(hold_decels(config))[:axis_count]
    decels += [decels[-1]] * (axis_count - len(decels)) + [0] * (MAX_AXES - axis_count)
    all_inputs = (1 << INPUT_COUNT) - 1
    return Config(
        invert=input_mask(inputs.active_high),
        enabled=all_inputs & ~input_mask(inputs.disabled),
        hard_limits=int(inputs.hard_limits),
        debounce=(ticks,) * INPUT_COUNT,
        hold_decel=four_axes(decels),
    )


def switch_input(present: int, axis: int, end: str) -> Input:
    """The input of an axis's switch at `end` ("min" or "max"): its own max input where the board
    has one, else the axis's one limit input (min and max switches on one pin, as on the Uno's
    shield)."""
    if end == "max" and present >> Input.limit(axis, True) & 1:
        return Input.limit(axis, True)
    return Input.limit(axis)
