"""Measuring the backlash on the emulator, against a simulated machine that alone knows it: the probe at a
block's corner (no hysteresis enters), the limit switch with its calibrated hysteresis taken off, a scattered
result refused, and the value written to the configuration with its comments and a backup."""

from __future__ import annotations

import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from backlash_helpers import STEPS_PER_MM, backlash_config
from quadstep.config import ConfigError, InputsConfig, load_config
from quadstep.config_file import set_backlash
from quadstep.machine import Target, open_machine
from quadstep.machine.backlash import (
    MeasureError, calibrate_switch, known_backlash, measure_with_probe, measure_with_switch,
)

REPO = Path(__file__).resolve().parents[2]
HYSTERESIS = 6.5  # the switch's, steps


def run_cli(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "quadstep.cli", *args], capture_output=True, text=True,
                          env={**os.environ, **env}, timeout=120)


def sim(backlash: tuple[float, float, float], jitter: float = 0.0) -> str:
    """X's switch at −400 with hysteresis and bounce, a block whose −X, −Y corner is at (4000, 4000) and a
    probe with hysteresis; the tool starts 0.5 mm outside the block's −X face, 1 mm inside its −Y edge."""
    axes = ""
    for i, (b, start) in enumerate(zip(backlash, (3800, 4400, -2000))):
        axes += f"[[axis]]\nstart = {start}\nbacklash = {b}\n"
        if i == 0:
            axes += (f"[axis.limit_min]\nat = -400.0\nhysteresis = {HYSTERESIS}\nbounce = 2\nbounce_ticks = 40\n"
                     f"jitter = {jitter}\n")
    return axes + """
[probe]
hysteresis = 1.5
[[probe.target]]
kind = "block"
x_min = 4000
x_max = 8000
y_min = 4000
y_max = 8000
z = -1000
"""


def machine_on(start_emulator, tmp_path: Path, backlash: tuple[float, float, float], jitter: float = 0.0,  # noqa: ANN001
               hysteresis_mm: float | None = None):  # noqa: ANN201
    path = tmp_path / "sim.toml"
    path.write_text(sim(backlash, jitter))
    config = backlash_config((0.1, 0.1, 0.1)).model_copy(update={"inputs": InputsConfig(debounce_ms=2)})
    if hysteresis_mm is not None:
        x = config.axes[0]
        x = x.model_copy(update={"backlash": x.backlash.model_copy(update={"switch_hysteresis": hysteresis_mm})})
        config = config.model_copy(update={"axes": (x, *config.axes[1:])})
    emu = start_emulator(free=True, tick_hz=32_000, axes=3, extra_args=["--machine", str(path)])
    return open_machine(Target(emulator=True), config, emulator=emu)


def test_the_probe_at_a_corner_measures_the_backlash_within_a_step(start_emulator, tmp_path: Path) -> None:  # noqa: ANN001
    rng = random.Random(7)
    for _ in range(3):
        b = (rng.uniform(0, 120), rng.uniform(0, 120), 5.0)
        with machine_on(start_emulator, tmp_path, b) as machine:
            x = measure_with_probe(machine, "X", toward=1, test="Y", test_toward=1, tries=2)
            assert x.accepted and abs(x.steps - b[0]) < 1.0, (x, b)
            assert x.mm == x.steps / STEPS_PER_MM and x.spread_steps == 0


def test_the_switch_measures_the_backlash_once_its_hysteresis_is_known(start_emulator, tmp_path: Path) -> None:  # noqa: ANN001
    with machine_on(start_emulator, tmp_path, (47.3, 0, 0), hysteresis_mm=HYSTERESIS / STEPS_PER_MM) as machine:
        result = measure_with_switch(machine, "X", tries=2, search=12)
        assert result.accepted and abs(result.steps - 47.3) < 1.0
        assert abs(result.sum_steps - (47.3 + HYSTERESIS)) < 1.0  # what a switch alone can see: their sum
        hysteresis = calibrate_switch(machine, "X", 47.3 / STEPS_PER_MM, tries=2, search=12)
        assert abs(hysteresis * STEPS_PER_MM - HYSTERESIS) < 1.0


def test_a_switch_without_a_calibrated_hysteresis_is_refused(start_emulator, tmp_path: Path) -> None:  # noqa: ANN001
    with machine_on(start_emulator, tmp_path, (20, 0, 0)) as machine:
        with pytest.raises(Exception, match="hysteresis is not calibrated"):
            measure_with_switch(machine, "X", search=12)


def test_a_scattered_result_is_refused_and_a_good_one_written(tmp_path: Path, emulator_binary: Path) -> None:
    config = tmp_path / "machine.toml"
    shutil.copy(REPO / "examples" / "router-uno.toml", config)
    config.write_text(config.read_text().replace("debounce_ms = 0.5", "debounce_ms = 2"))
    set_backlash(config, "X", mm=0.1, switch_hysteresis=HYSTERESIS / STEPS_PER_MM)
    (tmp_path / "scattered.toml").write_text(sim((30, 0, 0), jitter=4.0))
    env = {"QUADSTEP_EMULATOR": str(emulator_binary)}
    refused = run_cli("backlash", "measure", "--axis", "X", "--method", "switch", "--search", "12", "--config",
                      str(config), "--sim", str(tmp_path / "scattered.toml"), "--free", "--max-spread", "0.001",
                      env=env)
    assert refused.returncode == 1 and "refused: the tries spread" in refused.stderr
    (tmp_path / "clean.toml").write_text(sim((30, 0, 0)))
    written = run_cli("backlash", "measure", "--axis", "X", "--config", str(config), "--sim",
                      str(tmp_path / "clean.toml"), "--free", "--tries", "2", "--write", "--yes", env=env)
    assert written.returncode == 0, written.stderr
    measured = load_config(config).axes[0].backlash
    assert measured is not None and abs(measured.mm * STEPS_PER_MM - 30) < 1.0
    assert measured.switch_hysteresis == round(HYSTERESIS / STEPS_PER_MM, 6)  # the rest of the table kept
    assert "# mm/s for the slow approach whose latch sets zero" in config.read_text()  # and the comments
    assert "mm = 0.1\n" in (tmp_path / "machine.toml.bak").read_text()


def test_writing_keeps_the_file_when_the_result_would_not_load(tmp_path: Path) -> None:
    config = tmp_path / "machine.toml"
    shutil.copy(REPO / "examples" / "router-uno.toml", config)
    before = config.read_text()
    with pytest.raises(ConfigError, match="backlash.accel"):
        set_backlash(config, "X", mm=0.1, accel=10_000)  # more than the axis's max_accel
    assert config.read_text() == before and not (tmp_path / "machine.toml.bak").exists()
    with pytest.raises(ConfigError, match="no \\[\\[axes\\]\\] with name = 'Q'"):
        set_backlash(config, "Q", mm=0.1)


def test_the_calibration_takes_off_the_backlash_given_or_configured_and_refuses_none() -> None:
    config = backlash_config((0.1, 0.0, 0.0))  # Y has no [axes.backlash]
    assert known_backlash(config, "X") == 0.1 and known_backlash(config, "Y", 0.02) == 0.02
    with pytest.raises(MeasureError, match="Y: no backlash known: measure it with the probe first"):
        known_backlash(config, "Y")
