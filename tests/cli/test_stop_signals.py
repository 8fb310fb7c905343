"""Every stop request is a controlled stop: Ctrl-C, SIGTERM and SIGHUP bring whatever moves to rest with HOLD,
print where, and exit 130, at any moment (a job, homing, probing, start-up); an emulator the command started
never outlives it, SIGKILL included; a closed stdout ends quietly."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cli_helpers import cli_process, wait_for_child
from quadstep.link import Link
from quadstep.protocol import State, StatusReport
from relay import Relay

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
SIM = REPO / "examples" / "router-uno-machine.toml"
TICK_HZ = 32000
STEPS = re.compile(r"\((-?\d+) steps\)")


def status_of(url: str) -> StatusReport:
    with Link.open(url) as link:
        return link.status()


def free_tcp_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def shown_steps(out: str) -> list[int]:
    """The steps of the `machine: …` line."""
    line = next(line for line in out.splitlines() if line.startswith("machine: "))
    return [int(s) for s in STEPS.findall(line)]


def read_until(stream, text: str) -> str:  # noqa: ANN001
    """Lines from `stream` until one holds `text`."""
    seen = ""
    while text not in seen:
        line = stream.readline()
        assert line, f"the command ended before printing {text!r}: {seen}"
        seen += line
    return seen


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_a_job_as_ctrl_c_does(start_emulator, sig: signal.Signals) -> None:
    port = free_tcp_port()
    start_emulator(axes=3, tick_hz=TICK_HZ, extra_args=["--tcp", str(port)])  # real time: about 11 s
    with Relay(port) as relay:
        process = cli_process("run", "examples/demo.gcode", "--config", str(ROUTER), "--port", relay.url)
        relay.wait_done(10)  # well under way
        process.send_signal(sig)
        out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    lines = out.splitlines()
    assert lines[1].startswith("stopped at line ") and lines[1].endswith(" (HOLD)")
    status = status_of(f"socket://127.0.0.1:{port}")
    assert status.state == State.IDLE and status.alarm is None and status.queue_fill == 0
    assert shown_steps(out) == list(status.position[:3])
    assert "Traceback" not in err


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_homing_holds_and_says_where(start_emulator, sig: signal.Signals) -> None:
    emu = start_emulator(axes=3, tick_hz=TICK_HZ, extra_args=["--machine", str(SIM)])  # real time
    process = cli_process("home", "--config", str(ROUTER), "--port", emu.url)
    assert process.stderr is not None
    read_until(process.stderr, "Z: seeking the switch")  # Z first, 20 mm below its switch at 10 mm/s
    os.kill(process.pid, sig)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    assert f"quadstep home: interrupted{'' if sig == signal.SIGINT else ' (SIGTERM)'}: stopped (HOLD)" in err
    status = status_of(emu.url)
    assert status.state == State.IDLE and status.alarm is None  # a hold: no queue run dry (UNDERRUN)
    steps = shown_steps(out)
    assert steps == list(status.position[:3])
    assert 0 <= steps[2] < 8000  # stopped on its way up, short of the switch


def test_interrupted_probing_holds_and_says_where(start_emulator) -> None:
    port = free_tcp_port()
    start_emulator(axes=3, tick_hz=TICK_HZ, extra_args=["--machine", str(SIM), "--tcp", str(port)])
    with Relay(port) as relay:
        process = cli_process("probe", "Z=-30", "--feed", "1", "--config", str(ROUTER), "--port", relay.url)
        relay.wait_done(2)  # moving down at 1 mm/s: the plate is 20 mm below
        os.kill(process.pid, signal.SIGINT)
        out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    assert "quadstep probe: interrupted: stopped (HOLD)" in err
    status = status_of(f"socket://127.0.0.1:{port}")
    assert status.state == State.IDLE and status.alarm is None
    steps = shown_steps(out)
    assert steps == list(status.position[:3])
    assert -8000 < steps[2] < 0


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_while_connecting_is_one_line(tmp_path: Path, sig: signal.Signals) -> None:
    job = tmp_path / "job.nc"
    job.write_text("G1 X1 F600\n")
    with socket.create_server(("127.0.0.1", 0)) as silent:  # a board that never answers
        silent.settimeout(60)
        process = cli_process("run", str(job), "--config", str(ROUTER),
                              "--port", f"socket://127.0.0.1:{silent.getsockname()[1]}")
        connection, _ = silent.accept()
        with connection:
            assert connection.recv(1)  # the command asks who is there
            os.kill(process.pid, sig)
            out, err = process.communicate(timeout=30)
    assert process.returncode == 130
    assert err == f"quadstep run: interrupted{'' if sig == signal.SIGINT else ' (SIGTERM)'}\n"
    assert out == ""


def test_no_emulator_outlives_a_killed_command(emulator_binary: Path) -> None:
    process = cli_process("run", "examples/demo.gcode", "--config", str(ROUTER), "--emulator",
                          env={"QUADSTEP_EMULATOR": str(emulator_binary)})
    emulator = wait_for_child(process)
    process.kill()
    process.communicate(timeout=30)
    deadline = time.monotonic() + 30
    stat = Path(f"/proc/{emulator}/stat")
    while stat.exists() and stat.read_text().split(") ")[1][0] != "Z":
        assert time.monotonic() < deadline, f"quadstep-emu {emulator} still runs after its command was killed"
        time.sleep(0.05)


def test_check_into_a_closed_pipe_ends_quietly() -> None:
    read, write = os.pipe()
    os.close(read)  # as `| head -1` once it has its line
    process = subprocess.Popen([sys.executable, "-m", "quadstep.cli", "check", "examples/demo.gcode"],
                               stdout=write, stderr=subprocess.PIPE, text=True, cwd=REPO,
                               env=dict(os.environ, PYTHONPATH=str(REPO / "host")))
    os.close(write)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 141
    assert "Traceback" not in err and "BrokenPipeError" not in err
