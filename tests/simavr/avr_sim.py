"""Run the real AVR firmware in simavr through the qs-simavr harness.

`SimAvr` starts the harness on a pseudo-terminal (it prints `PORT /dev/pts/N`
like the emulator), so quadstep.link.Link talks to it exactly as to a board;
`run_feed` and `run_input` run it free, without a host, for deterministic
measurements. Both leave the step trace, the raw pin edges and a JSON stats
file behind (README.md in this directory describes them).
"""

from __future__ import annotations

import csv
import json
import os
import re
import select
import signal
import subprocess
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("QUADSTEP_BUILD", REPO / "build"))
HARNESS = BUILD / "simavr" / "qs-simavr"
BOARDS = {"uno": "atmega328p", "mega": "atmega2560"}
F_CPU = 16_000_000
START_TIMEOUT = 10.0
STOP_TIMEOUT = 10.0


class SimAvrError(RuntimeError):
    """The harness could not be built, started or run."""


def build(*targets: str) -> None:
    """`make firmware harness` (a no-op when up to date)."""
    result = subprocess.run(
        ["make", "-C", str(REPO), "-s", f"BUILD={BUILD}", *(targets or ("firmware", "harness"))],
        capture_output=True,
        text=True,
    )
    if result.returncode != 0:
        raise SimAvrError(f"make failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")


def elf_path(board: str) -> Path:
    return BUILD / "avr" / f"{board}.elf"


def avr_define(name: str, board: str = "uno") -> int:
    """A -D value of a board's build as avr.mk sets it (shared, or the board's own)."""
    out = subprocess.run(["make", "-C", str(REPO), "-s", "print-avr-vars"], capture_output=True, text=True,
                         check=True).stdout
    own = f"AVR_{board.upper()}_DEFINES="
    lines = [line for line in out.splitlines() if line.startswith(("AVR_DEFINES=", own))]
    match = re.search(rf"-D{name}=(\d+)", " ".join(lines))
    if not match:
        raise SimAvrError(f"{name} is not among the {board} build's defines:\n{out}")
    return int(match.group(1))


@dataclass
class Outputs:
    """Where a run leaves its files."""

    trace: Path
    edges: Path
    stats: Path

    @classmethod
    def in_dir(cls, directory: Path, name: str = "avr") -> Outputs:
        return cls(directory / f"{name}-trace.csv", directory / f"{name}-edges.csv", directory / f"{name}-stats.json")

    def args(self) -> list[str]:
        return ["--trace", str(self.trace), "--edges", str(self.edges), "--stats", str(self.stats)]

    def load_stats(self) -> dict:
        return json.loads(self.stats.read_text())

    def load_trace(self) -> np.ndarray:
        return load_trace(self.trace)

    def load_edges(self) -> list[tuple[int, str, int, int]]:
        with self.edges.open() as f:
            return [(int(r["cycle"]), r["pin"], int(r["axis"]), int(r["level"])) for r in csv.DictReader(f)]


def load_trace(path: Path) -> np.ndarray:
    """A `tick,axis,direction` CSV (the emulator's format) as an (N, 3) int64 array."""
    rows = np.loadtxt(path, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2)
    return rows.reshape(-1, 3)


def parse_summary(text: str) -> dict[str, int | str]:
    summary: dict[str, int | str] = {}
    for line in text.splitlines():
        key, sep, value = line.strip().partition("=")
        if sep and key and " " not in key:
            summary[key] = int(value) if value.lstrip("-").isdigit() else value
    return summary


class SimAvr:
    """qs-simavr serving the board's UART on a pseudo-terminal; use as a context manager."""

    def __init__(self, outputs: Outputs, board: str = "uno", elf: Path | None = None,
                 extra_args: Sequence[str] = ()) -> None:
        self.outputs = outputs
        self.args = [str(HARNESS), "--mcu", BOARDS[board], "--elf", str(elf or elf_path(board)), "--pty",
                     *outputs.args(), *extra_args]
        self.url = ""
        self.summary: dict[str, int | str] = {}
        self.returncode: int | None = None
        self._proc: subprocess.Popen[bytes] | None = None
        self._stderr = tempfile.TemporaryFile()

    def start(self) -> SimAvr:
        self._proc = subprocess.Popen(self.args, stdout=subprocess.PIPE, stderr=self._stderr,
                                      stdin=subprocess.DEVNULL)
        assert self._proc.stdout is not None
        line = _read_line(self._proc.stdout.fileno(), START_TIMEOUT)
        if not line.startswith("PORT "):
            self.stop()
            raise SimAvrError(f"{' '.join(self.args)} printed {line!r}, not `PORT <device>`:\n{self.stderr_text()}")
        self.url = line[5:].strip()
        return self

    def stderr_text(self) -> str:
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")

    def stop(self) -> dict[str, int | str]:
        """SIGTERM, wait, and return the exit summary; the output files are then complete."""
        if self._proc is not None:
            if self._proc.poll() is None:
                self._proc.send_signal(signal.SIGTERM)
                try:
                    self._proc.wait(STOP_TIMEOUT)
                except subprocess.TimeoutExpired:
                    self._proc.kill()
                    self._proc.wait()
            self.returncode = self._proc.returncode
            if self._proc.stdout is not None:
                self._proc.stdout.close()
            self._proc = None
            self.summary = parse_summary(self.stderr_text())
        return self.summary

    def __enter__(self) -> SimAvr:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _read_line(fd: int, timeout: float) -> str:
    data = b""
    deadline = time.monotonic() + timeout
    while not data.endswith(b"\n"):
        remaining = deadline - time.monotonic()
        if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
            break
        chunk = os.read(fd, 256)
        if not chunk:
            break
        data += chunk
    return data.decode(errors="replace")


def _run(args: list[str], timeout: float) -> str:
    result = subprocess.run(args, capture_output=True, timeout=timeout)
    if result.returncode != 0:
        raise SimAvrError(f"{' '.join(args)} exited {result.returncode}:\n{result.stderr.decode(errors='replace')}")
    return result.stderr.decode(errors="replace")


def run_feed(frames: bytes, outputs: Outputs, board: str = "uno", elf: Path | None = None,
             max_cycles: int = 4 * F_CPU, reply_file: Path | None = None, timeout: float = 120.0) -> dict:
    """Send ready-made sequenced frames as fast as flow control allows, free-running; returns the stats."""
    feed = outputs.stats.with_suffix(".feed")
    feed.write_bytes(frames)
    args = [str(HARNESS), "--mcu", BOARDS[board], "--elf", str(elf or elf_path(board)), "--feed", str(feed),
            "--max-cycles", str(max_cycles), *outputs.args()]
    if reply_file is not None:
        args += ["--output", str(reply_file)]
    _run(args, timeout)
    return outputs.load_stats()


def run_input(data: bytes, outputs: Outputs, reply_file: Path, board: str = "uno", elf: Path | None = None,
              max_cycles: int = F_CPU, timeout: float = 120.0) -> dict:
    """Put raw bytes on the line at its rate (no flow control), free-running until idle; returns the stats."""
    path = outputs.stats.with_suffix(".input")
    path.write_bytes(data)
    args = [str(HARNESS), "--mcu", BOARDS[board], "--elf", str(elf or elf_path(board)), "--input", str(path),
            "--output", str(reply_file), "--exit-when-idle", "--max-cycles", str(max_cycles), *outputs.args()]
    _run(args, timeout)
    return outputs.load_stats()
