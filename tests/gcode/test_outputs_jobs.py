"""Spindle, laser and coolant words in jobs: the OUTPUTS each stretch of a job runs under, on the emulator.

The emulator's output trace (tick, pins, duty) shows what the board's pins do; the step trace shows where the
motion was at that tick, so each change is checked against the line that asked for it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.planner.program import OutputState, Pause, SetOutputs
from quadstep.protocol import Output
from quadstep.cli import main
from quadstep.gcode import parse_gcode

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
XYZ = ("X", "Y", "Z")


def read_outputs(path: Path) -> list[tuple[int, int, int]]:
    rows = np.loadtxt(path, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2)
    return [tuple(int(v) for v in row) for row in rows.reshape(-1, 3)]


def laser_config(tmp_path: Path) -> Path:
    path = tmp_path / "laser.toml"
    path.write_text(ROUTER.read_text() + "\n[spindle]\ns_max = 1000\nlaser = true\n")
    return path


def test_spindle_words_set_the_outputs_in_line_order() -> None:
    program = parse_gcode("S 12000 M3\nM8 M7\nG0 X1\nT2 M6\nM9\nM4 S500\nM30", XYZ)
    states = [(i.line, i.state) for i in program.items if isinstance(i, SetOutputs)]
    assert states == [
        (1, OutputState(spindle=3, speed=12000)),
        (2, OutputState(spindle=3, speed=12000, mist=True, flood=True)),
        (4, OutputState(speed=12000)),  # off for the tool change ...
        (4, OutputState(spindle=3, speed=12000, mist=True, flood=True)),  # ... and on again after it
        (5, OutputState(spindle=3, speed=12000)),
        (6, OutputState(spindle=4, speed=500)),
        (7, OutputState(speed=500)),  # M30 turns everything off
    ]
    pause = next(i for i in program.items if isinstance(i, Pause))
    assert (pause.line, pause.tool, pause.reason) == (4, 2, "tool change to T2")


def test_a_spindle_job_rests_at_each_change_and_ends_off(start_emulator, tmp_path: Path, capsys) -> None:
    job = tmp_path / "spindle.gcode"
    job.write_text("G21 G90\nS500 M3\nG0 X10 Y10\nG1 X20 F600\nM8\nG1 X30\nM5 M9\nG0 X0 Y0\n")
    plan = load_job(job, CONFIG).plan
    trace, outputs = tmp_path / "trace.csv", tmp_path / "outputs.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz,
                         extra_args=["--outputs", str(outputs)])
    code = main(["run", str(job), "--config", str(ROUTER), "--port", emu.url])
    assert code == 0, capsys.readouterr().err
    emu.stop()
    half = round(65535 * 500 / 1000)
    ticks = np.cumsum(plan.segments.numpy()["n"])
    starts = {int(plan.segments.line[i]): int(ticks[i - 1]) if i else 0 for i in range(len(plan) - 1, -1, -1)}
    changes = read_outputs(outputs)
    assert [(pins, duty) for _, pins, duty in changes] == [
        (int(Output.ON), half), (int(Output.ON | Output.FLOOD), half), (0, 0)]
    # each from the tick the first move after its line starts (the machine at rest there: no laser mode)
    assert [tick for tick, _, _ in changes] == [starts[3], starts[6], starts[8]]


def test_a_laser_job_follows_the_speed_and_is_off_on_rapids(start_emulator, tmp_path: Path, capsys) -> None:
    config_path = laser_config(tmp_path)
    config = load_config(config_path)
    job = tmp_path / "laser.gcode"
    job.write_text("G21 G90 M4 S1000\nG0 X5 Y5\nG1 X25 F1200\nG1 Y25\nS500\nG1 X5\nG0 X0 Y0\nM5\n")
    plan = load_job(job, config).plan
    assert not plan.pauses
    outputs = tmp_path / "outputs.csv"
    emu = start_emulator(free=True, axes=3, tick_hz=config.tick_hz, extra_args=["--outputs", str(outputs)])
    code = main(["run", str(job), "--config", str(config_path), "--port", emu.url])
    assert code == 0, capsys.readouterr().err
    emu.stop()
    changes = read_outputs(outputs)
    duties = [duty for _, pins, duty in changes if pins & Output.ON]
    # the power ramps with the speed (a line per tick it changes), full at the feed, half after S500
    assert len(duties) > 100
    assert max(duties) == 65535
    half = [duty for tick, pins, duty in changes if pins & Output.ON and tick > changes[0][0] and duty < 65535]
    assert 32767 in half or 32768 in half
    assert changes[-1][1:] == (0, 0)  # off at the end


def test_no_stop_between_laser_lines(tmp_path: Path) -> None:
    """In laser mode a change of power runs on without stopping (GRBL's $32); without it the machine rests."""
    text = "G21 M3 S100 G1 X10 F600\nS200 X20\nS300 X30\n"
    laser = load_config(laser_config(tmp_path))
    path = tmp_path / "power.gcode"
    path.write_text(text)
    for config, rests in ((laser, False), (CONFIG, True)):
        plan = load_job(path, config).plan
        arrays = plan.segments.numpy()
        ends = [int(plan.move_ends[k]) - 1 for k in range(2)]
        at_rest = all(int(arrays["vn"][i, 0]) == 0 for i in ends)
        assert at_rest == rests
        assert [m.power for _, _, m in plan.outputs] == [round(65535 * s / 1000) for s in (100, 200, 300)]


@pytest.mark.parametrize("word", ["M3 S100", "M8"])
def test_skip_unsupported_runs_a_job_without_its_outputs(word: str) -> None:
    program = parse_gcode(f"{word}\nG1 X1 F60", XYZ, skip_unsupported=True)
    assert not any(isinstance(i, SetOutputs) for i in program.items)
