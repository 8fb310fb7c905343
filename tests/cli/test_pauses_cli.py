"""quadstep run at a tool change (T M6) and at an M0: what it asks for, and why it stops when nobody can answer."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

from cli_helpers import cli_process

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
TICK_HZ = 32000


def test_a_tool_change_asks_for_the_tool_and_goes_on_after_enter(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "tools.nc"
    job.write_text("G21 G90\nS1000 M3\nG1 X5 F1200\nT3 M6\nG1 X10\nM30\n")
    emu = start_emulator(free=True, axes=3, tick_hz=TICK_HZ)
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.PIPE)
    assert process.stderr is not None
    assert process.stderr.readline() == ("tool change at line 4: put in T3 (spindle and coolant off), then press "
                                         "Enter to continue, Ctrl-C to stop\n")
    out, err = process.communicate("\n", timeout=30)
    assert process.returncode == 0, err
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"


def test_m0_without_a_terminal_says_why_it_stopped(start_emulator, tmp_path: Path) -> None:
    job = tmp_path / "pause.nc"
    job.write_text("G21 G90\nG1 X5 F1200\nM0\nG1 X10\n")
    emu = start_emulator(free=True, axes=3, tick_hz=TICK_HZ)
    process = cli_process("run", str(job), "--config", str(ROUTER), "--port", emu.url, stdin=subprocess.DEVNULL)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 1
    assert ("stopped at line 3: M0 waits for Enter, and stdin is closed (not a terminal); run the job from a "
            "terminal, or give it what to answer on stdin") in err
    assert "stopped at line " in out


def test_a_long_wait_at_the_tool_change_prompt_is_not_a_silent_board(emulator_binary: Path, tmp_path: Path) -> None:
    """Nothing is owed while the job waits at rest for Enter: the line's quiet then is no silence of the board's,
    and the job goes on exactly however long the operator takes."""
    job = tmp_path / "tools.nc"
    job.write_text("G21 G90\nG0 Z0\nG0 X10 Y10\nG1 X20 F600\nT2 M6\nG1 X30 F600\nM30\n")
    process = cli_process("run", str(job), "--config", str(ROUTER), "--emulator", stdin=subprocess.PIPE,
                          env={"QUADSTEP_EMULATOR": str(emulator_binary)})
    assert process.stderr is not None
    prompt = ""
    while not prompt.startswith("tool change at line 5"):
        prompt = process.stderr.readline()
        assert prompt, "the job ended before its tool change"
    time.sleep(3.0)  # the operator's pause: twice the link's silence limit
    out, err = process.communicate("\n", timeout=30)
    assert process.returncode == 0, err
    assert "has not answered" not in err
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
