"""Jerk-limited (S-curve) jobs end to end: planned as cubic segments, streamed by the CLI to the real emulator.

The emulator's step trace must equal the host's prediction step for step, every axis must end exactly on the
job's last target, and the acceleration read back from the trace must change no faster than max_jerk allows
(within the quantisation docs/PLANNER.md derives).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from quadstep import job_scan
from quadstep.cli import _streamed, main
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.machine import file_feed
from quadstep.planner.stream import Stream
from quadstep.protocol import CubicSegment

from host_helpers import assert_trace_is_prediction, read_trace
from scurve_checks import jerk_violations, largest_jerk_phase_change

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
JERK = 20000.0  # mm/s³ on X and Y, half on Z


def jerk_config(tmp_path: Path) -> Path:
    text = (EXAMPLES / "router-uno.toml").read_text()
    text = text.replace("max_accel = 500\n", f"max_accel = 500\nmax_jerk = {JERK:g}\n")
    text = text.replace("max_accel = 200\n", f"max_accel = 200\nmax_jerk = {JERK / 2:g}\n")
    path = tmp_path / "router-scurve.toml"
    path.write_text(text)
    return path


JOB = """G21 G90 G17
G0 Z-1
G1 X20 Y5 F1800
G1 X40 Y5
G2 X50 Y15 I0 J10 F1200
G1 X50.3 Y40 F2400
G3 X30 Y40 R10.5
G1 X10 Y10 Z-2 F900
G4 P0.2
G0 X0 Y0 Z0
"""


@pytest.mark.parametrize("job", ["demo.gcode", "arcs"])
def test_scurve_jobs_run_exactly_as_predicted(job: str, start_emulator, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    config_path = jerk_config(tmp_path)
    config = load_config(config_path)
    source = EXAMPLES / job if job.endswith(".gcode") else tmp_path / "arcs.gcode"
    if not job.endswith(".gcode"):
        source.write_text(JOB)
    plan = load_job(source, config).plan
    assert isinstance(plan.segments, Stream)
    assert sum(isinstance(s, CubicSegment) for s in plan.segments.segments()) > 0.9 * len(plan)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=config.tick_hz)
    code = main(["run", str(source), "--config", str(config_path), "--port", emu.url, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    result = json.loads(out)
    assert result["completed"] and result["exact"]
    assert result["positions_steps"] == list(plan.end) == [0, 0, 0]
    assert result["motion_ticks"] == plan.duration_ticks
    assert result["link"]["frames_sent"] < len(plan) / 2  # cubic segments go several to a CUBIC_SEGMENTS frame
    summary = emu.stop()
    steps = read_trace(trace)
    assert_trace_is_prediction(steps, plan.segments.segments(), plan.start, axis_count=3, min_steps=10001)
    assert summary["segments_done"] == len(plan)
    assert jerk_violations(steps, plan, config) == []
    for axis in range(3):  # the bound is not vacuous: the jerk phases come near it
        change, jerk_term = largest_jerk_phase_change(steps, plan, axis)
        assert change > 0.5 * jerk_term


def fine_job(step: float, count: int) -> str:
    """`count` collinear moves of `step` mm out along X (then back in one move), as a fine engraving's."""
    lines = ["G21 G90", "G1 F600"] + [f"X{k * step:.4f}" for k in range(1, count + 1)]
    return "\n".join(lines + ["G1 X0", ""])


def test_fine_moves_run_exactly_as_predicted(
    start_emulator, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """256 moves of 0.01 mm at F600: planned (never refused) and run on the emulator step for step as
    predicted, every axis back on its target."""
    config_path = jerk_config(tmp_path)
    config = load_config(config_path)
    source = tmp_path / "fine.gcode"
    source.write_text(fine_job(0.01, 256))
    plan = load_job(source, config).plan
    assert isinstance(plan.segments, Stream) and plan.moves == 257
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=config.tick_hz)
    code = main(["run", str(source), "--config", str(config_path), "--port", emu.url, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    result = json.loads(out)
    assert result["completed"] and result["exact"]
    assert result["positions_steps"] == list(plan.end) == [0, 0, 0]
    assert result["motion_ticks"] == plan.duration_ticks
    emu.stop()
    expected = assert_trace_is_prediction(trace, plan.segments.segments(), plan.start, axis_count=3)
    assert len(expected.steps) == 2 * 256 * 4


def test_a_large_file_is_streamed_with_s_curves_to_its_exact_end(
    start_emulator, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`quadstep run` of a file over STREAM_BYTES (here lowered) on a jerk-limited machine: checked, then
    planned and sent a part at a time, each part going on from a state the plan before it kept (or from rest
    where the computer fell behind: tests/planner/test_scurve_continue.py and tests/machine/test_open_job.py
    hold that it goes on moving), every axis exactly at its end."""
    monkeypatch.setattr(_streamed, "STREAM_BYTES", 1000)
    monkeypatch.setattr(job_scan, "CHUNK_LINES", 60)  # parts of 60 lines, one part first
    monkeypatch.setattr(file_feed, "FIRST_PARTS", 1)
    config_path = jerk_config(tmp_path)
    config = load_config(config_path)
    lines = ["G21 G90 F2400", "G0 X70 Y50"]
    for k in range(1, 400):  # a circle's chords of 0.25 mm
        lines.append(f"G1 X{50 + 20 * math.cos(k / 80):.4f} Y{50 + 20 * math.sin(k / 80):.4f}")
    job = tmp_path / "streamed.gcode"
    job.write_text("\n".join(lines) + "\n")
    whole = load_job(job, config).plan
    emu = start_emulator(axes=3, tick_hz=config.tick_hz)
    code = main(["run", str(job), "--config", str(config_path), "--port", emu.url])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert out.splitlines()[0] == (
        f"{job}: 401 lines, {whole.moves} moves; every target inside the travel; planned and sent a "
        "part at a time"
    )
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    emu.stop()
