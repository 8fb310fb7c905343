"""`quadstep run JOB --resume`: a job whose host was killed mid-job (SIGKILL: nothing of it runs after) or at a
pause goes on, in a second command on the same board, from the exact move where motion stopped, and ends
exactly where the whole job ends."""

from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

from byte_faults import FaultyLine
from cli_helpers import cli_process

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.protocol import State, StatusReport

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
DEMO = REPO / "examples" / "demo.gcode"


def board_at_rest(url: str, timeout: float = 30.0) -> StatusReport:
    """Until the board, left alone, has stopped (its watchdog, or its queue run dry)."""
    deadline = time.monotonic() + timeout
    with Link.open(url) as link:
        while True:
            status = link.status()
            if status.state in (State.IDLE, State.ALARM, State.STARVED) and status.queue_fill == 0:
                return status
            assert time.monotonic() < deadline, f"the board still moves: {status}"
            time.sleep(0.05)


def resume(url: str, job: Path, answer: str = "") -> tuple[int, str, str]:
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", url, "--resume",
                          stdin=subprocess.PIPE)
    out, err = process.communicate(answer, timeout=120)
    return process.returncode, out, err


def test_a_job_whose_host_was_killed_goes_on_from_where_it_stopped(start_emulator, state_home: Path) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)  # real time: the demo takes about 11 s
    process = cli_process("run", str(DEMO), "--config", str(ROUTER), "--port", emu.url)
    assert process.stdout is not None
    assert process.stdout.readline().startswith(f"{DEMO}: 39 lines, ")  # streaming begins
    time.sleep(2.5)
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=30)
    stopped = board_at_rest(emu.url)
    whole = load_job(DEMO, CONFIG).plan
    assert 0 < stopped.segments_done < len(whole)  # mid-job
    assert list(state_home.glob("quadstep/*.job.json"))  # the journal kept it
    code, out, err = resume(emu.url, DEMO)
    assert code == 0, err
    assert f"resuming {DEMO} at line " in out  # the board ran dry or its watchdog stopped it: either kept the position
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    assert tuple(board_at_rest(emu.url).position[:3]) == whole.end
    assert not list(state_home.glob("quadstep/*.job.json"))  # done: nothing left to resume


def test_a_job_killed_at_its_pause_waits_there_again(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "pause.gcode"
    job.write_text("G21 G90\nG1 X10 Y5 F1200\nT2 M6\nG1 X30 F600\nG0 X0 Y0\n")
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.PIPE)
    assert process.stderr is not None
    assert process.stderr.readline().startswith("tool change at line 3: put in T2")
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=30)
    assert tuple(board_at_rest(emu.url).position[:3]) == CONFIG.to_steps((10.0, 5.0, 0.0))
    code, out, err = resume(emu.url, job, answer="\n")
    assert code == 0, err
    assert "tool change at line 3" in err  # offered again
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    assert tuple(board_at_rest(emu.url).position[:3]) == (0, 0, 0)


def test_nothing_to_resume_and_a_changed_file_are_refused(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "pause.gcode"
    job.write_text("G21 G90\nG1 X10 Y5 F1200\nM0\nG0 X0 Y0\n")
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    code, _, err = resume(emu.url, job)
    assert code != 0 and "nothing to resume" in err
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.PIPE)
    assert process.stderr is not None
    assert process.stderr.readline().startswith("paused at line 3 (M0)")
    process.send_signal(signal.SIGKILL)
    process.wait(timeout=30)
    job.write_text("G21 G90\nG1 X10 Y5 F1200\nM0\nG0 X1 Y0\n")
    code, _, err = resume(emu.url, job)
    assert code != 0 and "changed since the job stopped" in err
    assert tuple(board_at_rest(emu.url).position[:3]) == CONFIG.to_steps((10.0, 5.0, 0.0))  # nothing moved


def test_a_job_whose_port_dropped_goes_on_through_the_port_plugged_in_again(start_emulator) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    line = FaultyLine(emu.url, 0.0)  # a clean cable, pulled below
    process = cli_process("run", str(DEMO), "--config", str(ROUTER), "--port", line.port)
    assert process.stdout is not None
    assert process.stdout.readline().startswith(f"{DEMO}: 39 lines, ")
    time.sleep(2.5)
    line.close()  # the host's port goes dead under it
    out, err = process.communicate(timeout=60)
    assert process.returncode == 1 and "--resume goes on" in err, err
    with FaultyLine(emu.url, 0.0) as again:  # plugged in again (a new port, as USB may give)
        stopped = board_at_rest(again.port)
        assert 0 < stopped.segments_done < len(load_job(DEMO, CONFIG).plan)
        code, out, err = resume(again.port, DEMO)
        assert code == 0, err
        assert out.splitlines()[-1] == "every axis is exactly where the job put it"


def test_a_job_whose_host_froze_past_the_watchdog_goes_on_with_resume(start_emulator) -> None:
    """Frozen (SIGSTOP) longer than host_timeout on a board whose queue holds more than that: the board's
    watchdog brakes it to rest (ALARM HOST_LOST). The host, woken, reads that rather than calling the board
    silent, says why it stopped, and --resume goes on."""
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=127)
    process = cli_process("run", str(DEMO), "--config", str(ROUTER), "--port", emu.url)
    assert process.stdout is not None
    assert process.stdout.readline().startswith(f"{DEMO}: 39 lines, ")
    time.sleep(2.5)
    process.send_signal(signal.SIGSTOP)
    time.sleep(2.5 * CONFIG.host_timeout)
    process.send_signal(signal.SIGCONT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 1, err
    assert "firmware alarm HOST_LOST" in err and "(frozen, asleep or too busy)" in err, err
    assert "has not answered" not in err and "--resume goes on" in err
    code, out, err = resume(emu.url, DEMO)
    assert code == 0, err
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    assert tuple(board_at_rest(emu.url).position[:3]) == load_job(DEMO, CONFIG).plan.end
