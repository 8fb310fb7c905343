"""Jobs end to end: the CLI plans, checks and streams them to the real emulator over a pty.

The emulator's step trace must equal the host's bit-exact prediction of the plan,
step for step, and every axis must end exactly on the job's last target.
"""

from __future__ import annotations

import json
import os
import re
import signal
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from cli_helpers import cli_process, wait_for_child
from host_helpers import assert_trace_is_prediction, read_trace
from quadstep.cli import main
from quadstep.config import load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import load_state, save_state, state_path
from quadstep.protocol import SetPosition, State, StatusReport

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
ROUTER = EXAMPLES / "router-uno.toml"
CONFIG = load_config(ROUTER)
Capture = pytest.CaptureFixture[str]


def run_cli(args: list[str], capsys: Capture) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("job", ["demo.gcode", "moves.yaml"])
def test_examples_run_exactly_as_predicted(job: str, start_emulator, tmp_path: Path, capsys: Capture) -> None:
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    code, out, err = run_cli(["run", str(EXAMPLES / job), "--config", str(ROUTER), "--port", emu.url, "--json"], capsys)
    assert code == 0, err
    result = json.loads(out)
    plan = load_job(EXAMPLES / job, CONFIG).plan
    assert result["completed"] and result["exact"]
    assert result["positions_steps"] == list(plan.end) == [0, 0, 0]
    assert result["motion_ticks"] == plan.duration_ticks
    summary = emu.stop()
    assert_trace_is_prediction(trace, plan.segments.segments(), plan.start, axis_count=3, min_steps=10001)
    assert summary["segments_done"] == len(plan)


def test_a_job_starts_where_the_machine_stands(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    """Relative and absolute moves from a non-zero position, with arcs, land exactly."""
    job = tmp_path / "offset.gcode"
    job.write_text("G91 G1 X5 Y-3 F1200\nG2 X4 Y4 I2 J2\nG90 G1 X100.0004 Y50.0001 Z-2\nG0 Z0\n")
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    start = (12345, 6789, -40)
    with Link.open(emu.url) as link:
        link.send(SetPosition(positions=dict(enumerate(start))))
        link.drain()
    code, out, err = run_cli(["run", str(job), "--config", str(ROUTER), "--port", emu.url, "--json"], capsys)
    assert code == 0, err
    plan = load_job(job, CONFIG, start).plan
    assert json.loads(out)["positions_steps"] == [40000, 20000, 0] == list(plan.end)
    emu.stop()
    assert_trace_is_prediction(trace, plan.segments.segments(), start, axis_count=3)


def status_of(url: str) -> StatusReport:
    with Link.open(url) as link:
        return link.status()


def refused_run(start_emulator, capsys: Capture, job: Path, text: str) -> tuple[str, StatusReport]:
    """Run `text` as `job` on a fresh emulator, which must refuse it (exit 1): its stderr and the status after."""
    job.write_text(text)
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    code, _, err = run_cli(["run", str(job), "--config", str(ROUTER), "--port", emu.url], capsys)
    assert code == 1
    return err, status_of(emu.url)


def test_a_job_leaving_the_travel_moves_nothing(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    job = tmp_path / "far.gcode"
    err, status = refused_run(start_emulator, capsys, job, "G1 X10 Y10 F600\nG1 X20\nG1 Y250\nG1 X0 Y0\n")
    assert err == f"quadstep run: error: {job}: line 3: Y 250.000 mm is outside the travel 0.000 … 200.000 mm\n"
    assert (status.segments_done, status.motion_ticks, tuple(status.position[:3])) == (0, 0, (0, 0, 0))


def test_a_syntax_error_moves_nothing(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    job = tmp_path / "typo.gcode"
    err, status = refused_run(start_emulator, capsys, job, "G1 X10 F600\nG1 X20 Y5\nG1 X3O\n")
    assert err == f"quadstep run: error: {job}: line 3, column 6: 'O' has no number after it\n"
    assert status.segments_done == 0


def test_a_different_tick_rate_is_refused(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    config = tmp_path / "m.toml"
    config.write_text(ROUTER.read_text().replace("tick_hz = 32000", "tick_hz = 40000"))
    emu = start_emulator(axes=3, tick_hz=50000)
    code, _, err = run_cli(["run", str(EXAMPLES / "demo.gcode"), "--config", str(config), "--port", emu.url], capsys)
    assert code == 1
    assert err == (
        f"quadstep run: error: {config}: tick_hz = 40000, but the firmware ticks at 50000 Hz (identify); "
        "set tick_hz = 50000 in the configuration\n"
    )
    assert status_of(emu.url).segments_done == 0


def ctrl_c(process: subprocess.Popen[str]) -> None:
    """What the terminal does on Ctrl-C: SIGINT to every process of the foreground group."""
    os.killpg(process.pid, signal.SIGINT)


def test_ctrl_c_stops_the_machine_and_reports_where(start_emulator) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)  # real time: the demo takes about 11 s
    process = cli_process("run", "examples/demo.gcode", "--config", str(ROUTER), "--port", emu.url)
    assert process.stdout is not None
    first = process.stdout.readline()  # printed when streaming starts
    time.sleep(1.5)
    ctrl_c(process)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    lines = [first.rstrip("\n"), *out.splitlines()]
    assert lines[0].startswith("examples/demo.gcode: 39 lines, ")
    assert lines[1].startswith("stopped at line ") and lines[1].endswith(" (HOLD)")
    status = status_of(emu.url)
    assert status.state == State.IDLE and status.queue_fill == 0
    work = "  ".join(f"{a.name} {a.to_mm(s):.3f} mm" for a, s in zip(CONFIG.axes, status.position))
    shown = "  ".join(f"{a.name} {a.to_mm(s):.3f} mm ({s} steps)" for a, s in zip(CONFIG.axes, status.position))
    assert lines[2] == f"work (G54): {work}"  # no work offset stored: work = machine
    assert lines[3] == f"machine: {shown}"
    assert 0 < status.segments_done < len(load_job(EXAMPLES / "demo.gcode", CONFIG).plan)


@pytest.mark.parametrize("command", ["run", "send"])
def test_ctrl_c_with_the_emulator_started_by_the_command(emulator_binary: Path, tmp_path: Path, command: str) -> None:
    """The emulator the command starts runs in a session of its own: Ctrl-C reaches the command alone, which
    brings the machine to rest through it (HOLD) and reports where, instead of losing the port."""
    if command == "run":
        args = ["run", "examples/demo.gcode", "--config", str(ROUTER), "--emulator"]  # real time: about 11 s
    else:
        raw = tmp_path / "long.json"
        segment = {"n": 1000, "axes": [{"axis": 0, "direction": 1, "v0": 2048, "vn": 2048, "r": 0}]}
        stop = {"n": 1000, "axes": [{"axis": 0, "direction": 1, "v0": 2048, "vn": 0, "r": 0}]}
        raw.write_text(json.dumps({"segments": [segment] * 500 + [stop]}))  # 10 s at 50 kHz
        args = ["send", str(raw), "--emulator"]
    process = cli_process(*args, env={"QUADSTEP_EMULATOR": str(emulator_binary)})
    assert process.stdout is not None
    first = process.stdout.readline() if command == "run" else ""
    wait_for_child(process)  # `send` prints nothing first: its emulator started means it is past its imports
    time.sleep(1.5)
    ctrl_c(process)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    assert "Input/output error" not in err and "serial port failed" not in err
    lines = out.splitlines()
    if command == "run":
        assert first.startswith("examples/demo.gcode: 39 lines, ")
        assert lines[0].startswith("stopped at line ") and lines[0].endswith(" (HOLD)")
        assert lines[1].startswith("work (G54): X ") and lines[2].startswith("machine: X ")
        steps = [int(s) for s in re.findall(r"\((-?\d+) steps\)", lines[2])]
        assert len(steps) == 3 and any(steps)  # it stopped mid-job, somewhere along the way
    else:
        steps = json.loads(lines[-1].removeprefix("stopped (HOLD) at positions "))
        assert 0 < steps[0] < 500 * 500  # mid-file: each of the 500 segments moves X by 500 steps


def test_m0_waits_at_rest_for_the_operator(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "pause.gcode"
    job.write_text("G1 X10 Y5 F1200\nM0\nG1 X0 Y0\n")
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, axes=3, trace=trace, tick_hz=CONFIG.tick_hz)
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.PIPE)
    assert process.stderr is not None and process.stdin is not None
    assert process.stderr.readline() == "paused at line 2 (M0): press Enter to continue, Ctrl-C to stop\n"
    # the emulator writes its trace out whenever it goes idle: at the pause it holds the first move only
    steps = read_trace(trace)
    moved = [int(np.sum(steps[steps[:, 1] == axis, 2])) for axis in range(3)]
    assert tuple(moved) == CONFIG.to_steps((10.0, 5.0, 0.0))
    out, err = process.communicate("\n", timeout=30)
    assert process.returncode == 0, err
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    emu.stop()
    assert len(read_trace(trace)) == 2 * len(steps)


def test_check_summarises_without_a_machine(capsys: Capture) -> None:
    code, out, _ = run_cli(["check", str(EXAMPLES / "demo.gcode"), "--config", str(ROUTER), "--json"], capsys)
    assert code == 0
    summary = json.loads(out)
    plan = load_job(EXAMPLES / "demo.gcode", CONFIG).plan
    assert summary["segments"] == len(plan)
    assert summary["moves"] == plan.moves > 100
    assert summary["duration_s"] == pytest.approx(plan.duration_ticks / CONFIG.tick_hz)
    assert summary["distance_mm"] == pytest.approx(plan.distance_mm)
    for axis, config in zip(summary["axes"], CONFIG.axes):
        assert 0 < axis["peak_speed"] <= config.max_speed + CONFIG.tick_hz / 4096 / config.steps_per_mm
    code, out, _ = run_cli(["check", str(EXAMPLES / "demo.gcode"), "--config", str(ROUTER)], capsys)
    assert out.splitlines()[0] == (
        f"{EXAMPLES / 'demo.gcode'}: {summary['lines']} lines, {summary['moves']} moves, "
        f"{summary['segments']} segments ({summary['wire_bytes'] / 1000:.1f} kB on the wire)"
    )


def test_spindle_words_run_or_are_skipped_and_listed(tmp_path: Path, capsys: Capture) -> None:
    job = tmp_path / "spindle.gcode"
    job.write_text("M3 S10000\nG1 X10 F600\nM5\n")
    code, out, err = run_cli(["check", str(job), "--config", str(ROUTER)], capsys)
    assert code == 0, err
    assert "skipped" not in out
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER), "--skip-unsupported"], capsys)
    assert code == 0
    assert out.splitlines()[-1] == "skipped 3 unsupported words: line 1: M3, line 1: S10000, line 3: M5"


def test_plot_writes_a_png(tmp_path: Path, capsys: Capture) -> None:
    image = tmp_path / "demo.png"
    code, out, _ = run_cli(["plot", str(EXAMPLES / "demo.gcode"), "--config", str(ROUTER), "-o", str(image)], capsys)
    assert code == 0 and out == f"wrote {image}\n"
    data = image.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", data[16:24]) == (1200, 800)


def test_without_a_config_check_uses_the_default_machine_and_run_on_a_board_refuses(
    tmp_path: Path, capsys: Capture, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(["check", str(EXAMPLES / "demo.gcode")], capsys)
    assert code == 0
    assert err == "no configuration given: using the built-in default machine (the router of " \
                  "examples/router-uno.toml)\n"
    code, _, err = run_cli(["run", str(EXAMPLES / "demo.gcode"), "--port", "/dev/null"], capsys)
    assert code == 1
    assert err == (
        "quadstep run: error: no machine configuration: give --config FILE (or put quadstep.toml in this "
        "directory); examples/router-uno.toml is a commented one to start from\n"
    )


def test_run_and_check_work_in_the_stored_work_coordinates(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    stored = WorkCoordinates()
    stored.set_offset(1, "X", 10.0)
    save_state(state_path(ROUTER), stored)
    job = tmp_path / "offsets.gcode"
    job.write_text("G1 X5 Y2 F1200\nG10 L20 P2 X0\nG55 G1 X1\n")
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER), "--json"], capsys)
    assert code == 0
    summary = json.loads(out)
    assert summary["work_system"] == "G55"
    x = summary["axes"][0]
    assert (x["start_mm"], x["start_work_mm"], x["end_mm"], x["end_work_mm"]) == (0.0, -10.0, 16.0, 1.0)
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    code, out, err = run_cli(["run", str(job), "--config", str(ROUTER), "--port", emu.url, "--json"], capsys)
    assert code == 0, err
    result = json.loads(out)
    assert result["work_system"] == "G55" and result["positions_mm"][:2] == [16.0, 2.0]
    assert result["positions_work_mm"][:2] == [1.0, 2.0]
    kept = load_state(state_path(ROUTER))  # the job completed: what it left is kept
    assert kept.name == "G55" and kept.offsets[1] == {"X": 15.0} and kept.offsets[0] == {"X": 10.0}
    code, out, _ = run_cli(["run", str(job), "--config", str(ROUTER), "--port", emu.url], capsys)
    assert code == 0
    lines = out.splitlines()
    # From G55 this time: X5 is machine 20, where L20 puts G55's X0, so X1 is machine 21.
    assert lines[-3] == "work (G55): X 1.000 mm  Y 2.000 mm  Z 0.000 mm"
    assert lines[-2] == "machine: X 21.000 mm (8400 steps)  Y 2.000 mm (800 steps)  Z 0.000 mm (0 steps)"


def test_a_job_that_does_not_complete_leaves_the_stored_coordinates_alone(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "stop.gcode"
    job.write_text("G10 L2 P1 X3\nG1 X5 F1200\nM0\nG1 X0\n")
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.PIPE)
    out, err = process.communicate("", timeout=30)  # stdin closed at the pause: the job ends there
    assert process.returncode == 1, err
    assert "stopped at line 4" in out
    assert load_state(state_path(ROUTER)) == WorkCoordinates()


def test_a_broken_state_file_is_refused_naming_it(start_emulator, tmp_path: Path, capsys: Capture) -> None:
    path = state_path(ROUTER)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('{"version": 1, "coordinates": {"system": 9}}')
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    code, _, err = run_cli(["run", str(EXAMPLES / "demo.gcode"), "--config", str(ROUTER), "--port", emu.url], capsys)
    assert code == 1
    assert err == f"quadstep run: error: {path}: coordinates.system = 9: must be at most 6\n"
    assert status_of(emu.url).segments_done == 0


def test_check_counts_the_files_lines_and_says_what_follows_its_end(tmp_path: Path, capsys: Capture) -> None:
    job = tmp_path / "joined.nc"
    job.write_text("G21 G90\nY2\nG1 X1 F600\nM30\n\nG0 X5\n%\nG0 X6\n")  # two programs, one file
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER), "--json"], capsys)
    assert code == 0
    summary = json.loads(out)
    assert summary["lines"] == 4  # read up to the M30, as run reads it
    code, out, _ = run_cli(["check", str(job), "--config", str(ROUTER)], capsys)
    assert code == 0
    assert out.splitlines()[-1] == "line 4 ends the program (M2/M30): the 2 lines after it are not run"
    whole = tmp_path / "whole.nc"
    whole.write_text("G21\nY2\n")  # axis words alone move at rapid, as GRBL starts in G0
    code, out, _ = run_cli(["check", str(whole), "--config", str(ROUTER), "--json"], capsys)
    assert code == 0
    assert json.loads(out)["lines"] == 2  # the final newline ends line 2; it begins no line 3
    assert json.loads(out)["moves"] == 1
