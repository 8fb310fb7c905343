"""The AVR's written-out forms of core functions agree with their C forms (the host build's) on everything
they produce, in each board's layout: the cubic sums and checks (firmware/avr/cubic_sums.c against
firmware/core/qs_cubic_sums.c) for random axes weighted to the edges of every check, and the receive loop's
copy (firmware/avr/frame_rx.h against qs_frame_rx_copy) for random runs of bytes, delimiters among them. A
small AVR program (avr/forms_check.c) runs both in simavr and prints what it found."""

from __future__ import annotations

import re
import subprocess

import pytest

import avr_sim

BOARDS = {"uno": "atmega328p", "mega": "atmega2560"}


@pytest.mark.parametrize("board", sorted(BOARDS))
def test_avr_forms_equal_their_c_forms(avr_build: None, board: str) -> None:
    avr_sim.build("avr-forms-check")
    elf = avr_sim.BUILD / "simavr" / f"forms-{board}.elf"
    run = subprocess.run(["simavr", "-m", BOARDS[board], "-f", str(avr_sim.F_CPU), str(elf)],
                         capture_output=True, text=True, timeout=300)
    text = re.sub(r"\x1b\[[0-9;]*m", "", run.stdout + run.stderr)
    found = re.search(r"cubic-sums(?P<first>.*?) trials (\d+) checked (\d+) mismatches (\d+)", text)
    assert found, text
    trials, checked, mismatches = (int(found.group(k)) for k in (2, 3, 4))
    assert mismatches == 0, found.group("first")
    assert trials >= 6000 and checked >= trials // 6  # enough axes got as far as the slot
    found = re.search(r"rx-copy(?P<first>.*?) runs (\d+) mismatches (\d+)", text)
    assert found, text
    assert int(found.group(2)) >= 20000 and int(found.group(3)) == 0, found.group("first")
