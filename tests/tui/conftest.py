"""Fixtures for the jog and TUI tests: a small machine, and the real emulator behind a real pty."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from quadstep.config import MachineConfig, parse_config
from quadstep.emulator import Emulator
from quadstep.link import Link
from tui_helpers import MACHINE


@pytest.fixture
def machine() -> MachineConfig:
    return parse_config(MACHINE, "test machine")


@pytest.fixture
def paced_emulator(start_emulator, tmp_path: Path) -> Emulator:
    """3 axes in real time (50 kHz), as a board would run; step trace in tmp_path/trace.csv."""
    return start_emulator(free=False, axes=3, trace=tmp_path / "trace.csv")


@pytest.fixture
def paced_link(paced_emulator: Emulator) -> Iterator[Link]:
    with Link.open(paced_emulator.url) as link:
        yield link


@pytest.fixture
def fast_link(start_emulator) -> Iterator[Link]:
    """3 axes, free-running: incremental jogs finish at once."""
    emu = start_emulator(free=True, axes=3)
    with Link.open(emu.url) as link:
        yield link
