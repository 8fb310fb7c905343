"""The TUI's own cost while a job runs: the screen headless (Textual's pilot, no terminal), the status
read ten times a second as `quadstep tui` reads it, a zigzag job of LINES short moves run on the
emulator in real time. Prints the job's wall time, the process's CPU time over it, and the garbage
collector's collections meanwhile (count, longest, total): a collection holds every thread of the
process, the one feeding the board too.

    python3 tests/bench/bench_tui.py [--lines 3000]

Prints figures; asserts nothing."""

from __future__ import annotations

import argparse
import asyncio
import gc
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from tui_helpers import MACHINE, log_text, open_job, until  # noqa: E402

from quadstep.config import parse_config  # noqa: E402
from quadstep.machine import state_path  # noqa: E402
from quadstep.tui import QuadstepApp, Session, Target  # noqa: E402


class Collections:
    """The garbage collector's collections while a job's thread runs, by generation (ms)."""

    def __init__(self) -> None:
        self.pauses: dict[int, list[float]] = {0: [], 1: [], 2: []}
        self._began = 0.0
        gc.callbacks.append(self._seen)

    def _seen(self, phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            self._began = time.perf_counter()
        elif any(thread.name == "quadstep-job" for thread in threading.enumerate()):
            self.pauses[info["generation"]].append((time.perf_counter() - self._began) * 1000)


def zigzag(lines: int) -> str:
    return "G21 G90 F1500\n" + "".join(
        f"G1 X{(k % 60) * 0.5:.1f} Y{10 + (k % 2) * 0.5 + k // 60 * 0.2:.1f}\n"
        for k in range(1, lines)
    )


async def run_job(path: Path) -> tuple[float, float]:
    session = Session(Target(emulator=True, emulator_options={}), parse_config(MACHINE), None,
                      state_file=state_path(None))
    app = QuadstepApp(session, job_path=str(path))  # the status read as `quadstep tui` reads it
    async with app.run_test(size=(100, 30)) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None,
                    what="connection")
        cpu, wall = time.process_time(), time.monotonic()
        await open_job(pilot)
        await until(pilot, lambda: f"{path.name}: done" in log_text(app), timeout=3600, what="done")
        return time.monotonic() - wall, time.process_time() - cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=3000)
    args = parser.parse_args()
    collections = Collections()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "zigzag.gcode"
        path.write_text(zigzag(args.lines))
        wall, cpu = asyncio.run(run_job(path))
    print(f"TUI, a {args.lines}-line job at 10 status reads a second: {wall:.1f} s, "
          f"the process's CPU {cpu:.1f} s ({cpu / wall * 100:.0f} % of a core)")
    for generation, pauses in collections.pauses.items():
        if pauses:
            print(f"  generation {generation} collections: {len(pauses)}, longest {max(pauses):.1f} ms, "
                  f"in all {sum(pauses):.0f} ms")


if __name__ == "__main__":
    main()
