"""The real AVR firmware, run in simavr and driven by the host's Link over a
pseudo-terminal, makes exactly the steps the emulator makes for the same
segment streams (axis, direction and motion tick of every step), and both
make exactly the steps the host's model predicts."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import avr_scenarios
from avr_sim import Outputs, SimAvr, load_trace
from quadstep.kernel.engine_model import predict
from quadstep.link import Link
from quadstep.protocol import Segment, State, StatusReport

AXES = {"uno": 3, "uno-laser": 3, "mega": 4}
QUEUE = {"uno": 14, "uno-laser": 12, "mega": 32}


def stream(url: str, runs: list[list[Segment]]) -> StatusReport:
    """Send each run and wait for the board to come to rest after it."""
    with Link.open(url) as link:
        status = link.status()
        for run in runs:
            for segment in run:
                link.send(segment, timeout=60)
            status = link.wait_idle(timeout=120)
    return status


def first_difference(a: np.ndarray, b: np.ndarray) -> str:
    for i in range(min(len(a), len(b))):
        if not np.array_equal(a[i], b[i]):
            return f"step {i}: {a[i].tolist()} vs {b[i].tolist()}"
    return f"lengths {len(a)} vs {len(b)}"


def run_both(board: str, runs: list[list[Segment]], tmp_path: Path, start_emulator,
             send: Callable[[str, list[list[Segment]]], StatusReport] = stream) -> None:
    axes = AXES[board]
    expected = predict([s for run in runs for s in run], axis_count=axes)

    outputs = Outputs.in_dir(tmp_path, board)
    with SimAvr(outputs, board=board) as sim:
        avr_status = send(sim.url, runs)
    avr_steps = outputs.load_trace()

    emu_trace = tmp_path / "emu-trace.csv"
    emu = start_emulator(free=True, trace=emu_trace, axes=axes, queue=QUEUE[board])
    emu_status = send(emu.url, runs)
    emu.stop()
    emu_steps = load_trace(emu_trace)

    assert len(expected.steps) > 0
    assert np.array_equal(avr_steps, emu_steps), "AVR vs emulator: " + first_difference(avr_steps, emu_steps)
    assert np.array_equal(avr_steps, expected.steps), "AVR vs model: " + first_difference(avr_steps, expected.steps)
    for status in (avr_status, emu_status):
        assert status.state == State.IDLE
        assert list(status.position) == expected.positions
        assert status.motion_ticks == expected.motion_ticks
    # The harness counts motion ticks itself, from the engine's state; it
    # must agree with the firmware's own count.
    assert outputs.load_stats()["motion"]["motion_ticks"] == expected.motion_ticks


@pytest.mark.parametrize(
    "name",
    ["full_speed", "ramps_and_reversals", "random_runs", "cubic_runs", "quadratic_into_cubic"],
)
def test_uno_steps_match_emulator_and_model(name: str, avr_build: None, tmp_path: Path, start_emulator) -> None:
    axes = AXES["uno"]
    runs = {
        "full_speed": lambda: avr_scenarios.full_speed(axes),
        "ramps_and_reversals": lambda: avr_scenarios.ramps_and_reversals(axes),
        "random_runs": lambda: avr_scenarios.random_runs(axes, seed=7),
        "cubic_runs": lambda: avr_scenarios.cubic_runs(axes, seed=5),
        "quadratic_into_cubic": lambda: avr_scenarios.quadratic_into_cubic(axes),
    }[name]()
    run_both("uno", runs, tmp_path, start_emulator)


def test_mega_four_axes_match_emulator_and_model(avr_build: None, tmp_path: Path, start_emulator) -> None:
    run_both("mega", avr_scenarios.random_runs(AXES["mega"], seed=11, runs=2), tmp_path, start_emulator)


def test_mega_cubic_segments_match_emulator_and_model(avr_build: None, tmp_path: Path, start_emulator) -> None:
    run_both("mega", avr_scenarios.cubic_runs(AXES["mega"], seed=12, runs=1, shortest=1000), tmp_path, start_emulator)


@pytest.mark.parametrize("name", ["ramps_and_reversals", "random_runs"])
def test_uno_laser_build_quadratic_streams_match_emulator_and_model(name: str, avr_build: None, tmp_path: Path,
                                                                      start_emulator) -> None:
    """The laser build, whose segments are all quadratic (QS_CUBIC 0), steps as the Uno's own build."""
    axes = AXES["uno-laser"]
    runs = {
        "ramps_and_reversals": lambda: avr_scenarios.ramps_and_reversals(axes),
        "random_runs": lambda: avr_scenarios.random_runs(axes, seed=13),
    }[name]()
    run_both("uno-laser", runs, tmp_path, start_emulator)
