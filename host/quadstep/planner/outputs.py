"""The OUTPUTS message for each stretch of a job: the spindle or laser and coolant as the program
set them.

Without laser mode, M3 turns the spindle on, M4 on in reverse, at the power S gives. In laser mode
(the configuration's [spindle] laser, GRBL's $32) M3 is a constant power, M4 a power that follows
the speed of the move's dominant axis (PROTOCOL.md §5.5): the power S at the programmed feed and in
proportion below it, so the burn per mm is the same through every ramp and corner; G0 turns the
laser off. Messages are made per move, so a dynamic power is exact on every move of a path, not per
line.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..config import MachineConfig
from ..kernel.fixed import D
from ..protocol import Output, Outputs
from .program import OutputState

OFF = Outputs(outputs=0, power=0)


def is_dynamic(state: OutputState, config: MachineConfig) -> bool:
    """Whether the message depends on the move (a laser's M4, or any laser output during a G0)."""
    return config.spindle.laser and state.spindle != 5


def set_at_rest(state: OutputState, config: MachineConfig) -> bool:
    """Whether a change to `state` is sent where it is made, not with the next move (a laser's M4
    is)."""
    return not (config.spindle.laser and state.spindle == 4)


def output_message(
    state: OutputState, config: MachineConfig, unit: Sequence[float] = (), feed: float = 0.0
) -> Outputs:
    """The message for `state` on a move along `unit` (mm, normalised) at the programmed `feed`
    (mm/tick; inf: a rapid), or at rest (no unit)."""
    bits = (Output.MIST if state.mist else 0) | (Output.FLOOD if state.flood else 0)
    power = config.spindle.power(state.speed)
    if state.spindle == 5 or power == 0:
        return Outputs(outputs=int(bits), power=0)
    if not config.spindle.laser:
        bits |= Output.ON | (Output.REVERSE if state.spindle == 4 else 0)
        return Outputs(outputs=int(bits), power=power)
    # a rapid, or M4 at rest: the laser is off
    if feed == float("inf") or (state.spindle == 4 and not unit):
        return Outputs(outputs=int(bits), power=0)
    if state.spindle == 3:  # on at rest too (a dwell burns a dot)
        return Outputs(outputs=int(bits | Output.ON), power=power)
    steps = [abs(u) * a.steps_per_mm for u, a in zip(unit, config.axes)]
    axis = max(range(len(steps)), key=steps.__getitem__)
    speed = min(D, max(1, round(feed * steps[axis] * D)))
    return Outputs(
        outputs=int(bits | Output.ON | Output.DYNAMIC), power=power, axis=axis, speed=speed
    )
