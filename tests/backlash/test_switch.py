"""The limit-switch measurement on the emulator's simulated machine, its hysteresis calibrated
exactly: within a step of the truth for backlash 0 … 1 mm and hysteresis 4 … 10 steps (−1 exactly
only where both of the switch's points fall exactly on motor steps, which no count of steps can tell
apart); zero backlash gives 0, not −1 step; a result negative beyond the rounding, tries that spread
more than a step (a bounce longer than the debounce) and a bounce that trips the hard limit are
refused with the reason."""

from __future__ import annotations

import os
import random
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from backlash_helpers import STEPS_PER_MM, TICK_HZ, backlash_config
from quadstep.config import InputsConfig, load_config
from quadstep.config_file import set_backlash
from quadstep.emulator import Emulator
from quadstep.machine import Machine, Target, open_machine
from quadstep.machine.backlash import MeasureError, Measurement, measure_with_switch

REPO = Path(__file__).resolve().parents[2]
StartEmulator = Callable[..., Emulator]


@contextmanager
def x_switch(
    start_emulator: StartEmulator,
    tmp_path: Path,
    backlash: float,
    hysteresis: float,
    *,
    calibrated: float | None = None,
    debounce_ms: float = 2.0,
    bounce: tuple[int, int] = (2, 40),
    at: float = -400.0,
) -> Iterator[Machine]:
    """X's min switch at `at` with `hysteresis` and `bounce` (count, ticks), `backlash` steps; the
    configuration's switch_hysteresis is `calibrated` steps (default: the true one)."""
    sim = tmp_path / "switch.toml"
    sim.write_text(
        f"[[axis]]\nstart = 0\nbacklash = {backlash}\n[axis.limit_min]\nat = {at}\n"
        f"hysteresis = {hysteresis}\nbounce = {bounce[0]}\nbounce_ticks = {bounce[1]}\n"
        "[[axis]]\n[[axis]]\n"
    )
    config = backlash_config((0.1, 0.1, 0.1))
    x = config.axes[0]
    assert x.backlash is not None
    h = (hysteresis if calibrated is None else calibrated) / STEPS_PER_MM
    x = x.model_copy(update={"backlash": x.backlash.model_copy(update={"switch_hysteresis": h})})
    config = config.model_copy(
        update={"axes": (x, *config.axes[1:]), "inputs": InputsConfig(debounce_ms=debounce_ms)}
    )
    emu = start_emulator(free=True, tick_hz=TICK_HZ, axes=3, extra_args=["--machine", str(sim)])
    with open_machine(Target(emulator=True), config, emulator=emu) as machine:
        yield machine


def measure(machine: Machine, tries: int = 3) -> Measurement:
    return measure_with_switch(machine, "X", tries=tries, search=5.0, feed=4.0)


@pytest.mark.parametrize("hysteresis", (4.0, 6.0, 6.5))
def test_zero_backlash_is_measured_as_zero(
    start_emulator: StartEmulator, tmp_path: Path, hysteresis: float
) -> None:
    with x_switch(start_emulator, tmp_path, 0.0, hysteresis) as machine:
        result = measure(machine)
    assert result.accepted and result.steps == 0.0 and result.mm == 0.0, result


def test_backlash_0_to_1_mm_is_measured_within_a_step(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    rng = random.Random(11)
    for _ in range(6):
        backlash = rng.uniform(0, STEPS_PER_MM)
        hysteresis = rng.choice((4.0, 5.5, 6.5, 7.25, 8.0, 9.75, 10.0))
        with x_switch(start_emulator, tmp_path, backlash, hysteresis, at=-400.3) as machine:
            result = measure(machine)
        assert result.accepted and abs(result.steps - backlash) < 1.0, (
            backlash,
            hysteresis,
            result,
        )


def test_a_result_negative_beyond_the_rounding_is_refused(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    with x_switch(start_emulator, tmp_path, 0.0, 6.5, calibrated=9.5) as machine:
        result = measure(machine)
    assert not result.accepted and result.steps == 0.0
    assert "negative beyond the rounding" in result.refused, result.refused
    assert "switch_hysteresis is too large" in result.refused


def test_tries_spread_over_a_step_by_a_long_bounce_are_refused(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    """5 ms of debounce against a bounce of 10 ms: some edges are dropped and latched late."""
    with x_switch(
        start_emulator, tmp_path, 20.4, 6.5, debounce_ms=5.0, bounce=(5, 320), at=-400.3
    ) as m:
        result = measure_with_switch(m, "X", tries=4, search=5.0, feed=1.0)
    assert result.spread_mm <= result.bound_mm and result.spread_steps > 1.0  # within 0.01 mm, yet
    assert not result.accepted and "more than 1 step" in result.refused, result
    assert "debounce_ms" in result.refused


def test_a_bounce_that_trips_the_hard_limit_names_the_debounce(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    with (
        x_switch(start_emulator, tmp_path, 20.4, 6.5, debounce_ms=0.5, bounce=(3, 160)) as machine,
        pytest.raises(MeasureError) as error,
    ):
        measure_with_switch(machine, "X", tries=4, search=5.0, feed=1.0)
    text = str(error.value)
    assert "the switch bounced" in text and "debounce_ms = 0.5 ms" in text, text
    assert "Ctrl+X" in text and "STOP" in text and "stop()" not in text


def test_the_command_writes_zero_and_refuses_a_negative_result(
    tmp_path: Path, emulator_binary: Path
) -> None:
    config = tmp_path / "machine.toml"
    shutil.copy(REPO / "examples" / "router-uno.toml", config)
    config.write_text(config.read_text().replace("debounce_ms = 0.5", "debounce_ms = 2"))
    (tmp_path / "sim.toml").write_text(
        "[[axis]]\nstart = 0\nbacklash = 0\n[axis.limit_min]\nat = -400.0\nhysteresis = 6\n"
        "bounce = 2\nbounce_ticks = 40\n"
    )
    env = {**os.environ, "QUADSTEP_EMULATOR": str(emulator_binary)}
    command = [sys.executable, "-m", "quadstep.cli", "backlash", "measure", "--axis", "X"]
    command += ["--method", "switch", "--config", str(config), "--sim", str(tmp_path / "sim.toml")]
    command += ["--free", "--tries", "2", "--write", "--yes"]
    for calibrated, code, said in (
        (6, 0, "wrote"),
        (9, 1, "refused: the result is -4 steps, negative"),
    ):
        set_backlash(config, "X", mm=0.1, switch_hysteresis=calibrated / STEPS_PER_MM)
        done = subprocess.run(
            command, capture_output=True, text=True, env=env, timeout=120, check=False
        )
        assert done.returncode == code and said in done.stderr, done.stderr
        if code == 0:
            assert "X backlash: 0.0000 mm" in done.stdout, done.stdout
            backlash = load_config(config).axes[0].backlash
            assert backlash is not None and backlash.mm == 0.0
