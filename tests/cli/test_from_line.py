"""`quadstep run JOB --from-line N` on the real emulator: the approach, then the rest of the job,
ending exactly where the whole job ends; `check` shows the approach first; a line it cannot start
at moves nothing."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from host_helpers import assert_trace_is_prediction
from modal_job import JOB

from quadstep.cli import main
from quadstep.config import load_config
from quadstep.emulator import Emulator
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import load_state, state_path
from quadstep.protocol import SetPosition

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
Capture = pytest.CaptureFixture[str]
# Inches, relative segments, G55 set by G10, the spindle on, off and on again, a tool change;
# started at line 14.
START = (40000, 60000, -12000)  # steps: machine X 100, Y 150, Z -30 mm
APPROACH = ("starting at line 14: Z up to 0.000 mm (machine), X 25.400 Y 19.050 mm (G55) at "
            "rapid, spindle M3 S9000 on, flood coolant on, Z down to -1.016 mm (G55) at "
            "F254 mm/min; tool T2 (line 4) must be in the spindle")


def run_cli(args: list[str], capsys: Capture) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def run_args(job: Path, emu: Emulator, line: str) -> list[str]:
    return ["run", str(job), "--config", str(ROUTER), "--port", emu.url, "--from-line", line]


def emulator_at(start_emulator: Callable[..., Emulator], steps: tuple[int, ...],
                trace: Path | None = None) -> Emulator:
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    with Link.open(emu.url) as link:
        link.send(SetPosition(positions=dict(enumerate(steps))))
        link.drain()
    return emu


def test_a_run_from_a_line_ends_exactly_where_the_whole_job_ends(start_emulator, tmp_path: Path,
                                                                capsys: Capture) -> None:
    job = tmp_path / "pocket.gcode"
    job.write_text(JOB)
    trace = tmp_path / "trace.csv"
    emu = emulator_at(start_emulator, START, trace)
    code, out, err = run_cli(run_args(job, emu, "14") + ["--json"], capsys)
    assert code == 0, err
    result = json.loads(out)
    whole = load_job(job, CONFIG, START).plan
    part = load_job(job, CONFIG, START, from_line=14).plan
    assert result["completed"] and result["exact"]
    assert result["positions_steps"] == list(whole.end) == list(part.end)
    assert result["motion_ticks"] == part.duration_ticks < whole.duration_ticks
    assert result["work_system"] == "G54"  # M30
    g55 = load_state(state_path(ROUTER)).offsets[1]
    assert g55 == pytest.approx({"X": 25.4, "Y": 25.4, "Z": -5.08})
    emu.stop()
    rows = np.loadtxt(trace, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2).reshape(-1, 3)
    assert_trace_is_prediction(rows, part.segments.segments(), START, axis_count=3)


def test_the_run_says_how_it_gets_to_the_line(start_emulator, tmp_path: Path,
                                              capsys: Capture) -> None:
    job = tmp_path / "pocket.gcode"
    job.write_text(JOB)
    emu = emulator_at(start_emulator, START)
    code, out, err = run_cli(run_args(job, emu, "14"), capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[1] == APPROACH
    assert lines[-1] == "every axis is exactly where the job put it"
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER), "--from-line", "14"],
                           capsys)
    from_origin = APPROACH.replace("Z up to 0.000 mm (machine), ", "")  # Z is at the top already
    assert code == 0 and out.splitlines()[-1] == from_origin
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER), "--from-line", "14",
                            "--json"], capsys)
    assert code == 0 and json.loads(out)["approach"] == from_origin


def test_a_line_past_the_end_moves_nothing(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    job = tmp_path / "pocket.gcode"
    job.write_text(JOB)
    emu = emulator_at(start_emulator, START)
    code, _, err = run_cli(run_args(job, emu, "18"), capsys)
    assert code == 1
    assert err == f"quadstep run: error: {job}: line 18 is past the end of the job (17 lines)\n"
    with Link.open(emu.url) as link:
        status = link.status()
    assert (status.segments_done, status.motion_ticks, tuple(status.position[:3])) == (0, 0, START)


def test_the_option_is_in_the_run_commands_help(capsys: Capture) -> None:
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "--from-line N start the job at line N" in out
