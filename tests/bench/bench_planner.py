"""Planner benchmark: planning throughput and memory, link throughput, wire size, speed vs real time.

Prints figures only (docs/PLANNER.md records them); nothing is asserted.

    python3 tests/bench/bench_planner.py [--lines 100000]
"""

from __future__ import annotations

import argparse
import gc
import math
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))

from quadstep.config import load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.gcode import parse_gcode  # noqa: E402
from quadstep.job import Job, load_job  # noqa: E402
from quadstep.protocol.frame_choice import AVR_FRAMES, RUN_FRAMES  # noqa: E402
from quadstep.link import Link  # noqa: E402
from quadstep.planner.plan import plan_program  # noqa: E402

CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def short_moves_job(lines: int) -> str:
    """A Lissajous-like engraving in G1 moves of about 0.3 to 0.7 mm."""
    out = ["G21 G90 F1500", "G0 X150 Y100", "G1 Z-0.2 F300", "F1500"]
    for k in range(lines - len(out)):
        a = k * 0.004
        x = 150 + 100 * math.sin(a * 1.3) * math.cos(a * 0.021)
        y = 100 + 80 * math.sin(a * 0.9)
        out.append(f"G1 X{x:.3f} Y{y:.3f}")
    return "\n".join(out) + "\n"


def plan_figures(text: str) -> None:
    gc.collect()
    t0 = time.perf_counter()
    program = parse_gcode(text, CONFIG.axis_names, None, CONFIG.arc_tolerance)
    t1 = time.perf_counter()
    plan = plan_program(program, CONFIG)
    t2 = time.perf_counter()
    moves, segments = plan.moves, len(plan)
    print(f"job: {program.lines} lines of G-code, {len(text) / 1e6:.2f} MB, {moves} moves, "
          f"{plan.distance_mm / 1000:.2f} m, {plan.duration_s:.0f} s of motion")
    print(f"parse: {t1 - t0:.2f} s ({program.lines / (t1 - t0):,.0f} lines/s)")
    print(f"plan:  {t2 - t1:.2f} s ({moves / (t2 - t1):,.0f} moves/s, {segments / (t2 - t1):,.0f} segments/s, "
          f"{segments} segments, {segments / moves:.2f} per move)")
    print(f"planning is {plan.duration_s / (t2 - t0):,.0f}x faster than the machine runs it")
    print(f"planned job: {plan.segments.nbytes() / 1e6:.2f} MB of segment arrays "
          f"({plan.segments.nbytes() / segments:.0f} bytes per segment)")
    print(memory_figures(text))


def memory_figures(text: str) -> str:
    """Peak resident memory of a fresh process that parses and plans `text`, over its baseline."""
    path = REPO / "build" / "bench-planner-memory.gcode"
    path.parent.mkdir(exist_ok=True)
    path.write_text(text)
    probe = (  # VmHWM: the high-water mark of resident memory, in kB (Linux)
        "import re, sys; sys.path.insert(0, sys.argv[1]);"
        "hwm = lambda: int(re.search(r'VmHWM:\\s+(\\d+)', open('/proc/self/status').read()).group(1));"
        "from pathlib import Path; from quadstep.config import load_config; from quadstep.job import load_job;"
        "config = load_config(Path(sys.argv[2])); base = hwm();"
        "job = load_job(Path(sys.argv[3]), config); print(base, hwm())"
    )
    result = subprocess.run(
        [sys.executable, "-c", probe, str(REPO / "host"), str(REPO / "examples" / "router-uno.toml"), str(path)],
        capture_output=True, text=True, check=True,
    )
    base, peak = (int(x) for x in result.stdout.split())
    return (f"memory: a fresh process peaks at {peak / 1e3:.0f} MB resident reading and planning this job, "
            f"{(peak - base) / 1e3:.0f} MB above its {base / 1e3:.0f} MB after imports")


def link_figures(job: Job, text_bytes: int) -> None:
    plan = job.plan
    with Emulator(free=True, axes=len(CONFIG.axes), tick_hz=CONFIG.tick_hz) as emu, Link.open(emu.url) as link:
        t0 = time.perf_counter()
        for segment in plan.segments.segments():
            link.send(segment)
        status = link.wait_idle(timeout=600)
        elapsed = time.perf_counter() - t0
        sent = link.stats.bytes_sent
    exact = tuple(status.position[: len(CONFIG.axes)]) == plan.end
    print(f"link to the free-running emulator: {len(plan)} segments in {elapsed:.2f} s "
          f"({len(plan) / elapsed:,.0f} segments/s), positions exact: {exact}")
    print(f"wire: {sent / 1e6:.2f} MB sent for {plan.distance_mm:.0f} mm = {sent / plan.distance_mm:.1f} bytes/mm "
          f"({sent / len(plan):.1f} bytes per segment); "
          f"the G-code text is {text_bytes / plan.distance_mm:.1f} bytes/mm")
    for how, frames in (("as an Uno is sent it", AVR_FRAMES), ("in SEGMENTS runs", RUN_FRAMES)):
        real_time = job.wire_bytes(frames) / plan.duration_s
        print(f"wire rate needed in real time, {how}: {real_time / 1000:.1f} kB/s "
              f"({real_time * 10 / 500_000 * 100:.1f}% of 500 kbaud)")


def realistic_figures() -> None:
    path = REPO / "examples" / "demo.gcode"
    t0 = time.perf_counter()
    job = load_job(path, CONFIG)
    elapsed = time.perf_counter() - t0
    print(f"examples/demo.gcode: planned in {elapsed * 1000:.0f} ms for {job.plan.duration_s:.1f} s of motion "
          f"({job.plan.duration_s / elapsed:,.0f}x real time)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--lines", type=int, default=100_000)
    args = parser.parse_args()
    text = short_moves_job(args.lines)
    plan_figures(text)
    realistic_figures()
    path = REPO / "build" / "bench-planner-job.gcode"
    path.parent.mkdir(exist_ok=True)
    small = short_moves_job(min(args.lines, 20_000))
    path.write_text(small)
    link_figures(load_job(path, CONFIG), len(small.encode()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
