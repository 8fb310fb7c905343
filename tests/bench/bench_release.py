"""Key release → first deceleration tick through the real terminal driver (a pseudo-terminal), for both ways
the TUI learns of a release:

- kitty: a terminal with the kitty keyboard protocol reports the release (CSI 1;1:3 C); from writing it to the
  terminal to the first tick of the HOLD's deceleration;
- repeat timeout: any other terminal; the release is inferred when no repeat came within repeat_timeout; from
  writing the last repeat to the first deceleration tick (the true release falls between that repeat and the
  next, up to one repeat interval later, so this overstates by at most that).

Both run `quadstep tui --port PTY` against an emulator paced at the configuration's tick rate with an events
log (CLOCK_MONOTONIC, the clock of time.monotonic_ns()). Called by bench_jog.py."""

from __future__ import annotations

import os
import pty
import random
import select
import shutil
import sys
import time
from pathlib import Path

from quadstep.config import load_config
from quadstep.emulator import Emulator

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "examples" / "router-uno.toml"
INITIAL_DELAY, REPEAT_INTERVAL = 0.3, 0.04  # s, a terminal's key repeat


def _pump(fd: int, seconds: float, out: bytearray, until: bytes | None = None) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end and (until is None or until not in out):
        if select.select([fd], [], [], 0.02)[0]:
            try:
                out += os.read(fd, 65536)
            except OSError:
                return


def _holds(path: Path) -> list[int]:
    rows = path.read_text().splitlines()[1:] if path.exists() else []
    return [int(row.split(",")[2]) for row in rows if row.startswith("hold,")]


def release_latencies(count: int, seed: int, kitty: bool, workdir: Path) -> list[float]:
    """ms from each release (as the terminal wrote it) to the first deceleration tick, `count` X+ jogs."""
    rng = random.Random(seed)
    config_file = workdir / "router.toml"
    shutil.copy(CONFIG, config_file)  # the state file goes beside it
    config = load_config(config_file)
    events = workdir / ("kitty.csv" if kitty else "repeats.csv")
    emulator = Emulator(tick_hz=config.tick_hz, axes=len(config.axes), extra_args=("--events", str(events))).start()
    pid, fd = pty.fork()
    if pid == 0:
        os.environ["TERM"] = "xterm-256color"
        os.execvp(sys.executable, [sys.executable, "-m", "quadstep.cli", "tui", "--port", emulator.url,
                                   "--config", str(config_file)])
    out = bytearray()
    released: list[int] = []
    try:
        _pump(fd, 30.0, out, until=b"connected:")
        press, repeat, release = ((b"\x1b[1;1:1C", b"\x1b[1;1:2C", b"\x1b[1;1:3C") if kitty else
                                  (b"\x1b[C", b"\x1b[C", b""))
        os.write(fd, (b"\x1b[?27u\x1b[99u" if kitty else b"c"))  # kitty: its flags answer; then c: continuous
        _pump(fd, 0.5, out)
        for _ in range(count):
            held = rng.uniform(0.35, 0.8)
            start = time.monotonic()
            os.write(fd, press)
            last = time.monotonic_ns()
            time.sleep(INITIAL_DELAY)
            while time.monotonic() - start < held:
                os.write(fd, repeat)
                last = time.monotonic_ns()
                time.sleep(REPEAT_INTERVAL)
            if kitty:
                last = time.monotonic_ns()
                os.write(fd, release)
            released.append(last)
            deadline = time.monotonic() + 5.0
            while len(_holds(events)) < len(released) and time.monotonic() < deadline:
                _pump(fd, 0.02, out)
            if len(_holds(events)) < len(released):
                raise SystemExit(f"jog {len(released)} ({'kitty' if kitty else 'repeats'}) did not end with a HOLD")
            _pump(fd, 0.2, out)  # at rest, re-anchored
        os.write(fd, b"\x11")
        _pump(fd, 5.0, out)
    finally:
        os.waitpid(pid, 0)
        os.close(fd)
        emulator.stop()
    return [(hold - ns) / 1e6 for hold, ns in zip(_holds(events), released)]
