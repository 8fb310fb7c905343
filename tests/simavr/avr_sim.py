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
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from quadstep.port_process import PortProcess

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("QUADSTEP_BUILD", REPO / "build"))
HARNESS = BUILD / "simavr" / "qs-simavr"
BOARDS = {"uno": "atmega328p", "uno-laser": "atmega328p", "mega": "atmega2560"}
F_CPU = 16_000_000


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


def harness(board: str, elf: Path | None = None) -> list[str]:
    """The harness command running `elf` (by default the board's build) on the board's MCU."""
    return [str(HARNESS), "--mcu", BOARDS[board], "--elf", str(elf or elf_path(board))]


def avr_define(name: str, board: str = "uno") -> int:
    """A -D value of a board's build as avr.mk sets it (shared, or the board's own)."""
    out = subprocess.run(["make", "-C", str(REPO), "-s", "print-avr-vars"], capture_output=True, text=True,
                         check=True).stdout
    own = f"AVR_{board.upper().replace('-', '_')}_DEFINES="
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


class SimAvr(PortProcess):
    """qs-simavr serving the board's UART on a pseudo-terminal; use as a context manager."""

    error = SimAvrError
    stop_timeout = 10.0

    def __init__(self, outputs: Outputs, board: str = "uno", elf: Path | None = None,
                 extra_args: Sequence[str] = ()) -> None:
        super().__init__([*harness(board, elf), "--pty", *outputs.args(), *extra_args])
        self.outputs = outputs


def _run(args: list[str], outputs: Outputs, timeout: float) -> dict:
    """Run the harness free to its end; returns the stats it wrote."""
    result = subprocess.run([*args, *outputs.args()], capture_output=True, timeout=timeout)
    if result.returncode != 0:
        raise SimAvrError(f"{' '.join(args)} exited {result.returncode}:\n{result.stderr.decode(errors='replace')}")
    return outputs.load_stats()


def run_feed(frames: bytes, outputs: Outputs, board: str = "uno", elf: Path | None = None,
             max_cycles: int = 4 * F_CPU, reply_file: Path | None = None, timeout: float = 120.0,
             extra_args: Sequence[str] = ()) -> dict:
    """Send ready-made sequenced frames as fast as flow control allows, free-running; returns the stats."""
    feed = outputs.stats.with_suffix(".feed")
    feed.write_bytes(frames)
    args = [*harness(board, elf), "--feed", str(feed), "--max-cycles", str(max_cycles), *extra_args]
    if reply_file is not None:
        args += ["--output", str(reply_file)]
    return _run(args, outputs, timeout)


def run_input(data: bytes, outputs: Outputs, reply_file: Path, board: str = "uno", elf: Path | None = None,
              max_cycles: int = F_CPU, timeout: float = 120.0, until_idle: bool = True,
              extra_args: Sequence[str] = ()) -> dict:
    """Put raw bytes on the line at its rate (no flow control), free-running until idle (or, without
    `until_idle`, for all of `max_cycles`: the harness takes a hold's HOLDING for rest); returns the stats."""
    path = outputs.stats.with_suffix(".input")
    path.write_bytes(data)
    args = [*harness(board, elf), "--input", str(path), "--output", str(reply_file), "--max-cycles", str(max_cycles),
            *extra_args]
    if until_idle:
        args.append("--exit-when-idle")
    return _run(args, outputs, timeout)
