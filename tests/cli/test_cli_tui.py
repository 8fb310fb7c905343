"""`quadstep tui` from the command line: bad options refused, and a real terminal session."""

from __future__ import annotations

import os
import pty
import sys
from pathlib import Path

import pytest

from quadstep.cli import main
from tui_helpers import MACHINE, exit_code, read_terminal


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


def terminal_session(tmp_path: Path, emulator_binary: Path, script: list[tuple[bytes, float]],
                     *options: str) -> tuple[bytes, list[str]]:
    """`quadstep tui` in a real pseudo-terminal: write each chunk of `script` as a terminal would, wait its
    seconds, quit with Ctrl+Q; the screen output and the emulator's step trace."""
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
        os.execvp(sys.executable, [sys.executable, "-m", "quadstep.cli", "tui", "--emulator", "--trace", str(trace),
                                   "--config", str(config), *options])
    out = bytearray()
    try:
        read_terminal(fd, out, b"connected: emulator", 60)  # however loaded the machine
        for chunk, seconds in script:
            os.write(fd, chunk)
            read_terminal(fd, out, None, seconds)
        os.write(fd, b"\x11")  # Ctrl+Q
        read_terminal(fd, out, None, 5.0)
    finally:
        code = exit_code(pid, 10)
        os.close(fd)
    assert code == 0, "quadstep tui did not quit on Ctrl+Q"
    assert b"connected: emulator, 3 axes" in out
    return bytes(out), trace.read_text().splitlines()[1:]


def test_a_terminal_session_jogs_and_quits(tmp_path: Path, emulator_binary: Path) -> None:
    """The real terminal driver: an arrow key's escape sequence jogs X by 1 mm, Ctrl+Q quits cleanly."""
    _, steps = terminal_session(tmp_path, emulator_binary, [(b"\x1b[C", 2.0)], "--free")  # → as a terminal sends it
    assert len(steps) == 80 and all(line.endswith(",0,1") for line in steps)


def test_a_kitty_terminal_ends_a_continuous_jog_on_the_release(tmp_path: Path, emulator_binary: Path) -> None:
    """A terminal with the kitty keyboard protocol: asked for event types, it says it reports them, and a
    continuous jog ends on the key's release, long before the 5 s repeat timeouts would end it."""
    script = [
        (b"\x1b[?27u", 0.5),  # the terminal's answer to the flags query: event types on
        (b"\x1b[99u", 0.5),  # c, as the protocol reports every key: continuous mode
        (b"\x1b[1;1:1C", 0.4),  # → pressed (no repeats follow)
        (b"\x1b[1;1:3C", 1.5),  # → released
    ]
    out, steps = terminal_session(tmp_path, emulator_binary, script,
                                  "--first-repeat-timeout", "5", "--repeat-timeout", "5")
    assert b"\x1b[=27;1u" in out and b"\x1b[?u" in out  # the flags set, then asked for
    assert b"the terminal reports key releases" in out
    assert b"release: decelerated to rest" in out
    # 0.4 s at 12.5 mm/s and the braking: a few mm, where the timeouts would have let it run to the limit
    assert 0 < len(steps) < 800 and all(line.endswith(",0,1") for line in steps)
