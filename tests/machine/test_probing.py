"""G38.2–G38.5 through the machine layer, on the example router's simulated machine: the latched contact is the
plate's exact step (the carriage half the dead band behind the motor), a miss is an error only for G38.2/G38.4,
and moving away ends where contact is lost; `quadstep probe` prints the same."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.machine import Target, open_machine
from quadstep.machine.probing import ProbeError, probe

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SIM = REPO / "examples" / "router-uno-machine.toml"


def test_probing_toward_and_away_from_the_plate(start_emulator) -> None:
    emu = start_emulator(free=True, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(SIM)])
    machine = open_machine(Target(emulator=True), CONFIG, emulator=emu)
    with pytest.raises(ProbeError, match="G38.2: no contact made"):
        probe(machine, "38.2", (0, 0, -10), 5)
    missed = probe(machine, "38.3", (0, 0, -15), 5)
    assert not missed.found and missed.steps == (0, 0, -6000)
    hit = probe(machine, "38.2", (0, 0, -30), 2, work_offset=(0, 0, -20))
    # The plate's top is at motor -16000.5; power-up at -8000; the carriage leads the motor by 1.5 steps down.
    assert hit.found and hit.steps == (0, 0, -8002)
    assert hit.machine_mm[2] == pytest.approx(-20.005) and hit.work_mm[2] == pytest.approx(-0.005)
    with pytest.raises(ProbeError, match="touching already"):
        probe(machine, "38.2", (0, 0, -30), 2)
    off = probe(machine, "38.4", (0, 0, -10), 0.5)
    assert off.found and -8002 < off.steps[2] <= -7995  # the plate lets go a step of hysteresis and the band back
    machine.close()


def test_the_probe_command_prints_the_latched_position(emulator_binary: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "quadstep.cli", "probe", "Z=-45", "--feed", "5", "--config",
         str(REPO / "examples" / "router-uno.toml"), "--sim", str(SIM), "--free", "--json"],
        capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    out = json.loads(result.stdout)
    assert out["found"] and out["steps"] == [0, 0, -8002]
