"""quadstep run when the board stops making room: it resets mid-job, or an alarm flushes its queue while the job
waits for room. The command ends naming what happened, with the last position known; it never hangs."""

from __future__ import annotations

import socket
import subprocess
from pathlib import Path

from cli_helpers import cli_process
from relay import Relay

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
TICK_HZ = 32000


def free_tcp_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def zigzag(path: Path, moves: int) -> Path:
    """Short moves back and forth along Y while X advances 0.2 mm a move: a queue always full of corners."""
    lines = ["G21 G90"] + [f"G1 X{0.2 * i:.1f} Y{2 * (i % 2)} F3000" for i in range(1, moves + 1)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_board_reset_mid_job_ends_the_run_naming_the_reset(start_emulator, tmp_path: Path) -> None:
    port = free_tcp_port()
    tcp = ["--tcp", str(port)]
    board = start_emulator(axes=3, tick_hz=TICK_HZ, extra_args=tcp)  # real time: the job takes seconds
    with Relay(port) as relay:
        process = cli_process("run", str(zigzag(tmp_path / "job.nc", 300)), "--config", str(ROUTER),
                              "--port", relay.url)
        assert process.stdout is not None
        assert process.stdout.readline().startswith(f"{tmp_path / 'job.nc'}: ")  # streaming begins
        relay.wait_done(20)
        board.stop()
        start_emulator(axes=3, tick_hz=TICK_HZ, extra_args=tcp)  # the same board, afresh
        out, err = process.communicate(timeout=60)
    assert process.returncode == 1, err
    assert relay.reconnects >= 1  # (twice when it reached the old board once more as that one shut down)
    assert "quadstep run: error: the board was reset: segments done went back from " in err
    assert "last position known before: [" in err


def test_an_alarm_while_the_job_waits_for_room_ends_it_naming_the_alarm(start_emulator, tmp_path: Path) -> None:
    machine = tmp_path / "machine.toml"
    machine.write_text("[[axis]]\nstart = 0\n[axis.limit_max]\nat = 4000.5\n[[axis]]\nstart = 0\n"
                       "[[axis]]\nstart = 0\n")  # X's limit switch at 10 mm: the job crosses it
    emu = start_emulator(axes=3, tick_hz=TICK_HZ, queue=127, extra_args=["--machine", str(machine)])
    process = cli_process("run", str(zigzag(tmp_path / "job.nc", 100)), "--config", str(ROUTER),
                          "--port", emu.url, stdin=subprocess.DEVNULL)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 1, err
    assert "quadstep run: error: firmware alarm HARD_LIMIT at motion tick " in err
    assert "positions [40" in err  # X stopped at the switch (4000 steps and a few)
