"""`quadstep grbl` as a command: it says where it serves, a sender drives the emulator through the
`--link` path and TCP, and Ctrl-C ends it with the machine at rest and the link removed."""

from __future__ import annotations

import queue
import signal
import subprocess
import threading
import time
from pathlib import Path

from cli_helpers import cli_process
from grbl_client import GrblClient, mpos, report_fields


def printed_lines(process: subprocess.Popen[str]) -> queue.Queue[str]:
    """What the command prints, line by line, read by a thread of its own."""
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            lines.put(line.strip())

    threading.Thread(target=read, daemon=True).start()
    return lines


def test_quadstep_grbl_serves_the_link_path_and_tcp_until_interrupted(tmp_path: Path) -> None:
    link = tmp_path / "ttyGRBL"
    process = cli_process("grbl", "--emulator", "--free", "--link", str(link), "--tcp", "0")
    try:
        printed = printed_lines(process)
        served = printed.get(timeout=30)
        assert served.startswith("GRBL 1.1 on /dev/pts/") and served.endswith(f"(link {link})")
        tcp = printed.get(timeout=30)
        assert tcp.startswith("GRBL 1.1 on tcp://127.0.0.1:")
        assert link.is_symlink() and str(link.resolve()) == served.split()[3]
        with GrblClient(str(link)) as grbl:
            grbl.wait_banner()
            assert grbl.command("$I")[1] == "ok"
            assert grbl.command("G0 X1.5 Y2")[1] == "ok"
            report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
            assert mpos(report) == (1.5, 2.0, 0.0)
        with GrblClient(tcp.split()[-1].replace("tcp://", "socket://")) as grbl:
            grbl.wait_banner()
            report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
            assert mpos(report) == (
                1.5,
                2.0,
                0.0,
            )  # the same machine, where the first sender left it
    finally:
        process.send_signal(signal.SIGINT)
        deadline = time.monotonic() + 30
        while process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        if process.poll() is None:
            process.kill()
    assert process.wait() == 0
    assert not link.is_symlink()


def test_a_link_path_that_is_a_file_is_refused_and_kept(tmp_path: Path) -> None:
    kept = tmp_path / "notes.txt"
    kept.write_text("mine")
    process = cli_process("grbl", "--emulator", "--link", str(kept))
    _, err = process.communicate(timeout=60)
    assert process.returncode == 1
    assert f"--link {kept}: a file is there already (not a link)" in err
    assert kept.read_text() == "mine"


def test_config_and_m6_pause_reach_the_sender(tmp_path: Path) -> None:
    config = tmp_path / "quadstep.toml"
    config.write_text(
        (Path(__file__).resolve().parents[2] / "examples" / "router-uno.toml").read_text()
    )
    process = cli_process(
        "grbl", "--emulator", "--free", "--config", str(config), "--m6", "pause", "--tcp", "0"
    )
    try:
        printed = printed_lines(process)
        printed.get(timeout=30)
        tcp = printed.get(timeout=30)
        with GrblClient(tcp.split()[-1].replace("tcp://", "socket://")) as grbl:
            grbl.wait_banner()
            assert grbl.command("$112=600") == ([], "ok")
            assert "max_speed = 10" in config.read_text()
            assert grbl.stream_counting(["G0 X1", "T1 M6", "G0 X2"]) == ["ok"] * 3
            held = grbl.wait_status(lambda r: report_fields(r)["state"] == "Hold:0")
            assert mpos(held) == (1.0, 0.0, 0.0)
            grbl.realtime(ord("~"))
            report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
            assert mpos(report) == (2.0, 0.0, 0.0)
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=30)
    assert process.returncode == 0
