"""`quadstep run` of a large G-code file: the whole-file check's time, the time from its end to the
first move, the host's peak memory, and how much the running job's resident memory grows per
1,000 lines, on the real emulator (in real time).

The file is made here, line by line: rows of short G1 moves along X (0.4 mm), each row's end turned
by a G3 half circle, as a raster-like CAM pocket. After the first move the job runs for --run-s
seconds (the host planning and feeding as it goes), then is halted.

    python3 tests/bench/bench_big_run.py [--lines 2000000] [--run-s 10] [--max-jerk 20000]

With --max-jerk the plans are S-curves (docs/PLANNER.md, "S-curves"): a jerk-limited job keeps what
it ran, so its memory grows with the lines run.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))

from quadstep.config import MachineConfig, parse_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.job_scan import GcodeParts, scan_job  # noqa: E402
from quadstep.link import Link  # noqa: E402
from quadstep.machine import Machine  # noqa: E402
from quadstep.machine.file_feed import FileFeed, feed_file  # noqa: E402

ROW_MOVES = 250  # 0.4 mm moves a row: 100 mm


def write_job(path: Path, lines: int) -> None:
    """`lines` lines: a header, then rows along X joined by half circles, 1 mm apart in Y."""
    with path.open("w") as out:
        out.write("G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z0 F600\nF1800\n")
        written, row, x = 4, 0, 0.0
        while written < lines:
            step = 0.4 if row % 2 == 0 else -0.4
            for _ in range(min(ROW_MOVES, lines - written)):
                x += step
                out.write(f"G1 X{x:.3f}\n")
                written += 1
            if written < lines:
                row += 1
                if row % 150:  # the next row 1 mm on, through a half circle
                    out.write(f"{'G3' if step > 0 else 'G2'} Y{row % 150}.000 J0.5\n")
                else:  # back to the first row
                    out.write("G0 Y0\n")
                written += 1


def machine_config(max_jerk: float | None) -> MachineConfig:
    """A router at 400 steps/mm, 32 kHz, as the Uno; jerk-limited with `max_jerk` (mm/s³)."""
    axes = [
        {
            "name": n,
            "steps_per_mm": 400.0,
            "max_speed": 40.0,
            "max_accel": 500.0,
            "travel_min": -10.0,
            "travel_max": 400.0,
            "max_jerk": max_jerk,
        }
        for n in "XYZ"
    ]
    return parse_config({"tick_hz": 32000, "axes": axes})


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def resident_mb() -> float:
    """Resident memory now (Linux), where the peak would hide what the check freed."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * resource.getpagesize() / 2**20


def lines_per_s(feed: FileFeed, seconds: float) -> None:
    """Every `seconds` until the job ends: the line the machine is at, and the memory."""
    last, began = 0, time.monotonic()
    while feed.run.end is None and time.monotonic() - began < seconds:
        time.sleep(min(10.0, seconds))
        now = feed.run.progress
        print(
            f"  {time.monotonic() - began:5.0f} s: line {now.line} ({now.line - last} more), "
            f"{now.starvations} starvations; resident {resident_mb():.1f} MB, peak {peak_mb():.0f} MB",
            flush=True,
        )
        last = now.line


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=2_000_000)
    parser.add_argument("--run-s", type=float, default=10.0)
    parser.add_argument("--max-jerk", type=float, default=None, help="mm/s³: S-curve plans")
    args = parser.parse_args()
    config = machine_config(args.max_jerk)
    with tempfile.TemporaryDirectory() as folder:
        job = Path(folder) / "big.gcode"
        write_job(job, args.lines)
        print(f"{args.lines} lines, {job.stat().st_size / 2**20:.1f} MB; peak {peak_mb():.0f} MB")
        emulator = Emulator(
            binary=REPO / "build" / "native" / "quadstep-emu", axes=3, tick_hz=config.tick_hz
        ).start()
        try:
            with Link.open(emulator.url) as link:
                machine = Machine(link, config)
                began = time.monotonic()
                scan = scan_job(job, config, machine.position)
                checked = time.monotonic()
                print(
                    f"check: {checked - began:.2f} s ({scan.moves} moves); peak {peak_mb():.0f} MB"
                )
                feed = feed_file(machine, GcodeParts(job, config, machine.position))
                while link.status().motion_ticks == 0:
                    time.sleep(0.005)
                moving, resident = time.monotonic(), resident_mb()
                print(f"first move {moving - checked:.2f} s after the check's end")
                lines_per_s(feed, args.run_s)
                now = feed.run.progress
                grown = resident_mb() - resident
                print(
                    f"after {args.run_s:g} s: line {now.line}, {now.starvations} starvations, "
                    f"feed error {feed.error}; peak {peak_mb():.0f} MB"
                )
                print(
                    f"the running job's resident memory: {grown:+.1f} MB over {now.line} lines, "
                    f"{1000 * grown / max(now.line, 1):.2f} MB per 1,000 lines"
                )
                feed.run.halt("stop")
                feed.stop()
        finally:
            emulator.stop()


if __name__ == "__main__":
    main()
