"""`quadstep grbl` as a command: it says where it serves, a sender drives the emulator through the
`--link` path and TCP, and Ctrl-C ends it with the machine at rest and the link removed."""

from __future__ import annotations

import selectors
import signal
import subprocess
import time
from pathlib import Path

from cli_helpers import cli_process
from grbl_client import GrblClient, mpos, report_fields


def printed_line(process: subprocess.Popen[str], timeout: float = 30.0) -> str:
    assert process.stdout is not None
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)
        assert selector.select(timeout), "quadstep grbl printed nothing"
    return process.stdout.readline().strip()


def test_quadstep_grbl_serves_the_link_path_and_tcp_until_interrupted(tmp_path: Path) -> None:
    link = tmp_path / "ttyGRBL"
    process = cli_process("grbl", "--emulator", "--free", "--link", str(link), "--tcp", "0")
    try:
        served = printed_line(process)
        assert served.startswith("GRBL 1.1 on /dev/pts/") and served.endswith(f"(link {link})")
        tcp = printed_line(process)
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
