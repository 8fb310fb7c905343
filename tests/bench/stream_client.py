"""A sender in a process of its own, as UGS or CNCjs are.

`python3 stream_client.py PORT LINES` opens PORT (the front door's pseudo-terminal), streams the
first two lines of the file LINES by character counting and waits for rest, prints `READY`, then on
a line from stdin streams the rest and prints `DONE <first line sent> <at rest>` (time.monotonic(),
the system's clock that every process shares; rest is seen by polling `?`)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "helpers"))

from grbl_client import GrblClient, report_fields  # noqa: E402


def idle(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def main(port: str, lines_file: str) -> None:
    lines = Path(lines_file).read_text().splitlines()
    with GrblClient(port) as grbl:
        grbl.wait_banner()
        grbl.stream_counting(lines[:2])
        grbl.wait_status(idle)
        print("READY", flush=True)
        sys.stdin.readline()
        begun = time.monotonic()
        grbl.stream_counting(lines[2:])
        grbl.wait_status(idle, timeout=600)
        print(f"DONE {begun} {time.monotonic()}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
