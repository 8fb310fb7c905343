"""The check made on every connection: a firmware without cubic segments (the Uno's laser build) is
refused a configuration whose plans need them, S-curves or backlash taken up while moving, with the
axis, the setting and what to do instead; the same configuration without them is taken."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import BacklashConfig, MachineConfig, load_config
from quadstep.machine import MachineError
from quadstep.machine.agreement import check_agreement
from quadstep.protocol import Board, Capability, IdentifyReply

REPO = Path(__file__).resolve().parents[2]
LASER = load_config(REPO / "examples" / "laser-uno.toml")
EVERY = (
    Capability.QUADRATIC_SEGMENTS | Capability.CUBIC_SEGMENTS | Capability.CUBIC_RUNS | Capability.RASTER
)
LASER_BUILD = EVERY & ~(Capability.CUBIC_SEGMENTS | Capability.CUBIC_RUNS)


def identity(capabilities: int) -> IdentifyReply:
    return IdentifyReply(protocol_version=3, fw_major=0, fw_minor=1, fw_patch=0, board=Board.ATMEGA328P,
                         axis_count=3, queue_capacity=12, speed_shift=12, n_max=1022, tick_hz=32_000,
                         capabilities=capabilities, next_seq=0, boot_id=1, raster_ring=128)


def with_axis(config: MachineConfig, index: int, **update: object) -> MachineConfig:
    axes = list(config.axes)
    axes[index] = axes[index].model_copy(update=update)
    return config.model_copy(update={"axes": axes})


def test_a_laser_configuration_is_taken_by_the_laser_build() -> None:
    check_agreement(identity(LASER_BUILD), LASER, "laser-uno.toml")


def test_s_curves_need_cubic_segments() -> None:
    jerk = with_axis(LASER, 1, max_jerk=20_000.0)
    check_agreement(identity(EVERY), jerk, "laser-uno.toml")
    with pytest.raises(MachineError, match=r"^laser-uno.toml: axes\[1\].max_jerk = 20000, but the firmware "
                                           r"has no cubic .*quadstep flash --board uno$"):
        check_agreement(identity(LASER_BUILD), jerk, "laser-uno.toml")


def test_backlash_taken_up_while_moving_needs_cubic_segments() -> None:
    taken_up = with_axis(LASER, 0, backlash=BacklashConfig(mm=0.1))
    check_agreement(identity(EVERY), taken_up, "laser-uno.toml")
    with pytest.raises(MachineError, match=r"^laser-uno.toml: axes\[0\].backlash is compensated.*"
                                           r"backlash.compensate = false"):
        check_agreement(identity(LASER_BUILD), taken_up, "laser-uno.toml")
    known_only = with_axis(LASER, 0, backlash=BacklashConfig(mm=0.1, compensate=False))
    check_agreement(identity(LASER_BUILD), known_only, "laser-uno.toml")
