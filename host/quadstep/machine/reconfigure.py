"""A machine's configuration changed while it is connected (a setting written by a sender, docs/
SENDERS.md): at rest, the new one checked against the firmware as at connect, then used by every
program planned after; the inputs' settings sent to the board again."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..config import MachineConfig
from ..protocol import Capability, State
from .agreement import check_agreement
from .errors import MachineError
from .inputs import config_message
from .units import hold_decels

if TYPE_CHECKING:
    from .machine import Machine


def check_config(machine: Machine, config: MachineConfig, source: str) -> None:
    """MachineError unless `machine` could take `config` now."""
    if machine.busy:
        raise MachineError("the configuration changes only at rest")
    check_agreement(machine.identity, config, source)
    for old, new in zip(machine.config.axes, config.axes):
        if old.backlash_steps and old.steps_per_mm != new.steps_per_mm:
            raise MachineError(
                f"{source}: axis {old.name} has its backlash taken up in steps; change its "
                "steps_per_mm in the file and connect again"
            )
    if [a.name for a in config.axes] != [a.name for a in machine.config.axes]:
        raise MachineError(f"{source}: the axes changed; connect again")


def adopt_config(machine: Machine, config: MachineConfig, source: str) -> None:
    """Use `config` from now on (check_config first); the board's inputs set again if they
    changed."""
    check_config(machine, config, source)
    old, machine.config = machine.config, config
    machine.decels = hold_decels(config)
    machine.takeups.config = config
    identity = machine.identity
    if config.inputs != old.inputs and identity.capabilities & Capability.LIMIT_INPUTS:
        if machine.link.status().state in (State.IDLE, State.ALARM):
            machine.link.send(config_message(config, identity.axis_count))
            machine.link.drain(timeout=5)
