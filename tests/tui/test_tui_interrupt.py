"""Ctrl-C in the TUI, as in the other commands: any motion brought to rest with HOLD, then the line a job was
stopped at and the position printed, exit code 130; through the pilot during a job and through a real terminal."""

from __future__ import annotations

import os
import pty
import signal
import sys
from pathlib import Path

import pytest

from quadstep.cli.tui import parting_lines
from quadstep.config import MachineConfig
from quadstep.machine import state_path
from quadstep.tui import QuadstepApp, Session, Target
from tui_helpers import MACHINE, exit_code, read_terminal, until, open_job


async def test_ctrl_c_holds_a_running_job_and_says_where(machine: MachineConfig, emulator_binary: Path,
                                                         tmp_path: Path) -> None:
    job = tmp_path / "long.gcode"
    job.write_text("G21 G90\nG1 X30 F60\n")  # 30 s: Ctrl-C lands mid-move even on a loaded machine
    session = Session(Target(emulator=True, emulator_options={"binary": emulator_binary}), machine,
                      state_file=state_path(None))
    app = QuadstepApp(session, job_path=str(job), poll_interval=0.05)
    async with app.run_test(size=(100, 32)) as pilot:
        await until(pilot, lambda: session.connected and app.machine.snapshot is not None, what="connection")
        emulator = session.emulator
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.done > 0,
                    what="the job to move")
        await pilot.press("ctrl+c")
    assert app.interrupted and emulator is not None and emulator.summary is not None
    assert emulator.summary["state"] == "IDLE" and emulator.summary["alarm"] == "NONE"  # a hold, not an underrun
    at = int(emulator.summary["position_0"])
    assert 0 < at < 2400
    parting = session.parting
    assert parting is not None and parting.end is not None and parting.end.held
    lines = parting_lines(parting)
    assert lines[0] == "stopped at line 2 (HOLD)"
    assert lines[1].startswith("work (G54): X ")
    assert lines[2].startswith(f"machine: X {at / 80:.3f} mm ({at} steps)  Y 0.000 mm (0 steps)")


def tui_in_a_terminal(tmp_path: Path, emulator_binary: Path) -> tuple[int, int]:
    """`quadstep tui --emulator` started in a new pseudo-terminal: its pid and the terminal's master side."""
    config = tmp_path / "machine.toml"
    config.write_text("tick_hz = 50000\n" + "".join(
        "[[axes]]\n" + "".join(f"{key} = {value!r}\n" for key, value in axis.items()) for axis in MACHINE["axes"]))
    pid, fd = pty.fork()
    if pid == 0:  # the child: quadstep tui in a terminal, SIGHUP as a terminal gives it (not ignored as under nohup)
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
        os.environ["TERM"] = "xterm-256color"
        os.environ["QUADSTEP_EMULATOR"] = str(emulator_binary)
        os.execvp(sys.executable, [sys.executable, "-m", "quadstep.cli", "tui", "--emulator", "--config", str(config)])
    return pid, fd


@pytest.mark.parametrize("stop", ["ctrl-c", "SIGTERM", "SIGHUP"])
def test_a_stop_in_a_terminal_quits_and_prints_the_position(tmp_path: Path, emulator_binary: Path,
                                                            stop: str) -> None:
    """Ctrl-C, and SIGTERM or SIGHUP (the terminal closed) likewise."""
    pid, fd = tui_in_a_terminal(tmp_path, emulator_binary)
    out = bytearray()
    try:
        assert read_terminal(fd, out, b"connected: emulator", 60), bytes(out[-2000:])
        if stop == "ctrl-c":
            os.write(fd, b"\x03")  # Ctrl-C as the terminal sends it in raw mode
        else:
            os.kill(pid, getattr(signal, stop))
        read_terminal(fd, out, b"(0 steps)", 20)
    finally:
        code = exit_code(pid, 20)
        os.close(fd)
    assert code == 130
    assert b"machine: X 0.000 mm (0 steps)  Y 0.000 mm (0 steps)  Z 0.000 mm (0 steps)" in out


def test_closing_the_terminal_ends_the_tui_and_its_emulator(tmp_path: Path, emulator_binary: Path) -> None:
    """The terminal window closed (its master side gone: SIGHUP, and every write to it fails): the TUI
    still brings the machine to rest and exits, and its emulator with it; nothing is left running."""
    pid, fd = tui_in_a_terminal(tmp_path, emulator_binary)
    out = bytearray()
    try:
        assert read_terminal(fd, out, b"connected: emulator", 60), bytes(out[-2000:])
        emulators = children_of(pid)
        assert len(emulators) == 1
    finally:
        os.close(fd)  # the window closes
    code = exit_code(pid, 30)
    assert code is not None, "quadstep tui was still running 30 s after its terminal closed"
    assert code == 130
    assert not os.path.exists(f"/proc/{emulators[0]}") or "Z (zombie)" in Path(f"/proc/{emulators[0]}/status").read_text()


def children_of(pid: int) -> list[int]:
    """The processes whose parent is `pid` (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found
