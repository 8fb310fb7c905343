"""`quadstep grbl` is one command among the others on one board: what a sender did through it (a
move, a work zero set with G10 L20) is where `quadstep run` starts from afterwards, and what `run`
left (its position, the work system it ended in) is what a sender finds in the next `quadstep grbl`,
with the `$10` it set (kept in the configuration file, as GRBL keeps it in EEPROM). Each command a
process of its own, on one emulator kept running and serving TCP."""

from __future__ import annotations

import json
import signal
from collections.abc import Callable
from pathlib import Path

from cli_helpers import cli_process
from grbl_client import GrblClient, report_fields
from test_grbl_cli import printed_lines

from quadstep.config import load_config
from quadstep.emulator import Emulator
from quadstep.link import Link

REPO = Path(__file__).resolve().parents[2]
JOB = "G55\nG0 X1 Y1\nG1 Z-1 F300\n"  # in the work system the sender zeroed


def sender_session(
    where: list[str], lines: list[str], at_rest: tuple[str, ...] = ()
) -> tuple[list[str], str]:
    """`quadstep grbl` as a process of its own, a sender over TCP sending `lines` one by one (send
    and wait), then once the machine is at rest `at_rest` (settings) and `$#`; returns what `$#`
    said and the report then. The command ended by Ctrl-C, as a user ends it."""
    process = cli_process("grbl", *where, "--tcp", "0")
    try:
        printed = printed_lines(process)
        printed.get(timeout=60)
        tcp = printed.get(timeout=60)
        with GrblClient(tcp.split()[-1].replace("tcp://", "socket://")) as grbl:
            grbl.wait_banner()
            for line in lines:
                assert grbl.command(line)[1] == "ok", line
            grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
            for line in at_rest:
                assert grbl.command(line)[1] == "ok", line
            offsets, answer = grbl.command("$#")
            assert answer == "ok"
            report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=60)
    assert process.returncode == 0
    return offsets, report


def test_a_senders_moves_and_work_zero_carry_into_run_and_back(
    start_emulator: Callable[..., Emulator], tmp_path: Path
) -> None:
    config_file = tmp_path / "router.toml"
    config_file.write_text((REPO / "examples" / "router-uno.toml").read_text())
    config = load_config(config_file)
    board = start_emulator(free=True, tick_hz=config.tick_hz, axes=3, extra_args=["--tcp", "0"])
    where = ["--config", str(config_file), "--port", board.url]

    offsets, report = sender_session(
        where, ["G0 X10 Y20 Z-5", "G10 L20 P2 X0 Y0 Z0", "G0 X15"], at_rest=("$10=0",)
    )
    assert "[G55:10.000,20.000,-5.000]" in offsets
    assert report_fields(report)["WPos"] == "15.000,20.000,-5.000"  # $10=0: work positions, G54
    assert "status_mask = 0" in config_file.read_text()

    (tmp_path / "job.nc").write_text(JOB)
    ran = cli_process("run", str(tmp_path / "job.nc"), *where, "--json")
    out, err = ran.communicate(timeout=120)
    assert ran.returncode == 0, err
    result = json.loads(out)
    assert result["completed"] and result["exact"]
    assert tuple(result["positions_steps"]) == config.to_steps((11.0, 21.0, -6.0))
    assert result["work_system"] == "G55"

    offsets, report = sender_session(where, ["G0 X0 Y0"])  # in G55, where `run` left the machine
    assert "[G55:10.000,20.000,-5.000]" in offsets
    assert report_fields(report)["WPos"] == "0.000,0.000,-1.000"  # still $10=0
    with Link.open(board.url) as link:
        assert tuple(link.status().position[:3]) == config.to_steps((10.0, 20.0, -6.0))
