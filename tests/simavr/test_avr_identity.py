"""The board's identity: protocol version 3, its capabilities and the boot id it keeps in EEPROM."""

from __future__ import annotations

from pathlib import Path

from avr_sim import Outputs, SimAvr

from quadstep.link import Link
from quadstep.protocol import PROTOCOL_VERSION, Board, Capability, State


def test_the_uno_names_its_version_and_a_boot_id_from_its_eeprom(avr_build: None, tmp_path: Path) -> None:
    """The simulator loads the ELF's EEPROM image (the reset count, 0), as a programmer writing the .eeprom
    section would: the reset moves the count on to 1. (A board flashed without it starts from erased
    EEPROM, 0xFFFF, and its first reset is 0.)"""
    with SimAvr(Outputs.in_dir(tmp_path, "uno"), board="uno") as sim:
        with Link.open(sim.url) as link:
            ident = link.identify()
            status = link.status()
    assert (ident.protocol_version, ident.board) == (PROTOCOL_VERSION, Board.ATMEGA328P) == (3, 1)
    assert ident.capabilities & Capability.STARVATION_PAUSES
    assert ident.boot_id == 1
    assert status.state == State.IDLE
