"""The one check that the firmware can run what the configuration plans, made on every
connection."""

from __future__ import annotations

from ..config import MachineConfig
from ..kernel.fixed import N_MAX
from ..protocol import IdentifyReply
from .errors import MachineError


def check_agreement(identity: IdentifyReply, config: MachineConfig, source: str) -> None:
    """Refuse a firmware whose tick rate, axes or segment length differ from what the plans assume.

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
