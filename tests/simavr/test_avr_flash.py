"""Each board's build fits the flash its bootloader leaves (byte counts, exact): the Uno's Optiboot takes
512 of the ATmega328P's 32,768 bytes, the Mega's bootloader 8,192 of the ATmega2560's 262,144."""

from __future__ import annotations

import subprocess

import pytest

import avr_sim

ROOM = {"uno": 32_256, "uno-laser": 32_256, "mega": 253_952}


def flash_bytes(board: str) -> int:
    """What avrdude writes: the program and its initialised data (avr-size -A)."""
    out = subprocess.run(["avr-size", "-A", str(avr_sim.elf_path(board))], capture_output=True, text=True,
                         check=True).stdout
    sections = {parts[0]: int(parts[1]) for parts in (line.split() for line in out.splitlines()) if len(parts) >= 3
                and parts[1].isdigit()}
    return sections[".text"] + sections.get(".data", 0)


@pytest.mark.parametrize("board", sorted(ROOM))
def test_the_build_fits_beside_its_bootloader(avr_build: None, board: str) -> None:
    assert 0 < flash_bytes(board) <= ROOM[board]
