"""Backlash take-ups on the board: the real AVR firmware in simavr makes exactly the steps of the emulator and
of the host's prediction for compensated streams (docs/BACKLASH.md), their cubic windows included."""

from __future__ import annotations

from pathlib import Path

import avr_scenarios
from quadstep.protocol.cubic import CubicSegment
from test_avr_steps import AXES, run_both


def test_uno_take_ups_match_emulator_and_model(avr_build: None, tmp_path: Path, start_emulator) -> None:  # noqa: ANN001
    runs = avr_scenarios.takeups(AXES["uno"])
    assert all(any(isinstance(s, CubicSegment) for s in run) for run in runs)
    run_both("uno", runs, tmp_path, start_emulator)
