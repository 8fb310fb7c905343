"""`quadstep tui` from the command line: bad options refused, and a real terminal session."""

from __future__ import annotations

import os
import pty
import select
import sys
import time
from pathlib import Path

import pytest

from quadstep.cli import main
from tui_helpers import MACHINE


def test_bad_timeouts_are_refused_naming_the_option(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["tui", "--emulator", "--repeat-timeout", "0"]) == 1
    assert "repeat_timeout = 0.0: must be greater than 0" in capsys.readouterr().err
    assert main(["tui", "--emulator", "--first-repeat-timeout", "0.1", "--repeat-timeout", "0.2"]) == 1
    assert "repeat_timeout = 0.2: must be at most first_repeat_timeout = 0.1" in capsys.readouterr().err


def test_emulator_options_need_the_emulator(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["tui", "--port", "/dev/null", "--free"]) == 1
    assert "--free and --trace apply only with --emulator" in capsys.readouterr().err


def test_a_bad_config_is_refused_before_anything_starts(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "machine.toml"
    config.write_text("tick_hz = 50000\n[[axes]]\nname = 'X'\nsteps_per_mm = 80\nmax_speed = 900\n"
                      "max_accel = 500\ntravel_min = 0\ntravel_max = 40\n")
    assert main(["tui", "--emulator", "--config", str(config)]) == 1
    assert "axes[0].max_speed = 900.0: must be at most 468.75 mm/s" in capsys.readouterr().err


def _pump(fd: int, seconds: float, out: bytearray) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if select.select([fd], [], [], 0.05)[0]:
            try:
                out += os.read(fd, 65536)
            except OSError:
                return


def test_a_terminal_session_jogs_and_quits(tmp_path: Path, emulator_binary: Path) -> None:
    """The real terminal driver: an arrow key's escape sequence jogs X by 1 mm, Ctrl+Q quits cleanly."""
    config = tmp_path / "machine.toml"
    axes = "".join(
        f"[[axes]]\nname = '{a['name']}'\nsteps_per_mm = {a['steps_per_mm']}\nmax_speed = {a['max_speed']}\n"
        f"max_accel = {a['max_accel']}\ntravel_min = {a['travel_min']}\ntravel_max = {a['travel_max']}\n"
        for a in MACHINE["axes"]
    )
    config.write_text(f"tick_hz = 50000\n{axes}")
    trace = tmp_path / "trace.csv"
    pid, fd = pty.fork()
    if pid == 0:  # the child: quadstep tui in a terminal
        os.environ["TERM"] = "xterm-256color"
        os.environ["QUADSTEP_EMULATOR"] = str(emulator_binary)
        os.execvp(sys.executable, [sys.executable, "-m", "quadstep.cli", "tui", "--emulator", "--free",
                                   "--trace", str(trace), "--config", str(config)])
    out = bytearray()
    try:
        _pump(fd, 4.0, out)
        os.write(fd, b"\x1b[C")  # → as a terminal sends it
        _pump(fd, 2.0, out)
        os.write(fd, b"\x11")  # Ctrl+Q
        _pump(fd, 5.0, out)
    finally:
        deadline = time.monotonic() + 10
        done, status = os.waitpid(pid, os.WNOHANG)
        while not done and time.monotonic() < deadline:
            time.sleep(0.05)
            done, status = os.waitpid(pid, os.WNOHANG)
        os.close(fd)
        if not done:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            pytest.fail("quadstep tui did not quit on Ctrl+Q")
    assert os.waitstatus_to_exitcode(status) == 0
    assert b"connected: emulator, 3 axes" in out
    steps = trace.read_text().splitlines()[1:]
    assert len(steps) == 80 and all(line.endswith(",0,1") for line in steps)
