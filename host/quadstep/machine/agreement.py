"""The one check that the firmware can run what the configuration plans, made on every
connection."""

from __future__ import annotations

from ..config import MachineConfig
from ..kernel.fixed import N_MAX
from ..protocol import Capability, IdentifyReply
from .errors import MachineError


def check_agreement(identity: IdentifyReply, config: MachineConfig, source: str) -> None:
    """Refuse a firmware whose tick rate, axes or segment length differ from what the plans assume,
    or that lacks the cubic segments the plans need.

    `source` names the configuration in the message (its file, or "default configuration").
    """
    if identity.tick_hz != config.tick_hz:
        raise MachineError(
            f"{source}: tick_hz = {config.tick_hz}, but the firmware ticks at {identity.tick_hz} "
            f"Hz (identify); set tick_hz = {identity.tick_hz} in the configuration"
        )
    if identity.axis_count < len(config.axes):
        raise MachineError(
            f"{source}: {len(config.axes)} axes configured, the firmware drives "
            f"{identity.axis_count}"
        )
    if identity.n_max < N_MAX:
        raise MachineError(
            f"the firmware's n_max is {identity.n_max}; quadstep plans segments of up to {N_MAX} "
            "ticks"
        )
    if not identity.capabilities & Capability.CUBIC_SEGMENTS:
        _check_quadratic_only(config, source)


def _check_quadratic_only(config: MachineConfig, source: str) -> None:
    """A firmware built without cubic segments (the Uno's laser build) runs neither S-curves nor
    backlash taken up while moving, which are planned as cubic segments."""
    for i, axis in enumerate(config.axes):
        if axis.max_jerk is not None:
            raise MachineError(
                f"{source}: axes[{i}].max_jerk = {axis.max_jerk:g}, but the firmware has no cubic "
                "(jerk-limited) segments (the Uno's laser build); remove max_jerk, or write the "
                "Uno's own build with quadstep flash --board uno"
            )
        if axis.backlash_steps:
            raise MachineError(
                f"{source}: axes[{i}].backlash is compensated, but the firmware has no cubic "
                "segments to take it up with (the Uno's laser build); set backlash.compensate = "
                "false, or write the Uno's own build with quadstep flash --board uno"
            )
