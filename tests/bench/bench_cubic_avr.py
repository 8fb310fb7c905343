#!/usr/bin/env python3
"""Cubic segments on the Uno, measured in simavr on the real binary: the step interrupt with three
axes in jerk phases (every axis's q and b change every tick), at constant acceleration and at a steady
speed, beside the quadratic path; the main loop's cycles per CUBIC_SEGMENT; the wire bytes of a
chained 3-axis segment; and the most segments a second the board takes while three axes step in jerk
phases (flow-controlled, no tick lost).

    python3 tests/bench/bench_cubic_avr.py [--quick]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "simavr"))

import avr_scenarios  # noqa: E402
import avr_sim  # noqa: E402
from quadstep.protocol import encode  # noqa: E402
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.motion import CubicAxis
from quadstep.protocol.cubic_run import CubicSegments, SpeedChain, pack  # noqa: E402
from quadstep.protocol.frames import run_limit  # noqa: E402

F_CPU = avr_sim.F_CPU
SIGMA = 1 << 31
WORK = avr_sim.BUILD / "bench-cubic"


def jerk_stream(n: int, count: int, axes: int = 3) -> list[CubicSegment]:
    return avr_scenarios.jerk_phases(n, count, axes)


def steady_stream(n: int, count: int, accel: int) -> list[CubicSegment]:
    """Three axes at 0.6 step per tick, accelerating by `accel` per tick (0: steady), no jerk."""
    segs = [CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, speed=int(0.6 * SIGMA), accel=accel) for a in range(3)))]
    segs += [CubicSegment(n=n) for _ in range(count - 2)]
    segs.append(CubicSegment(n=1, axes=tuple(CubicAxis(axis=a, speed=0) for a in range(3))))
    return segs


def in_runs(segs: list[CubicSegment], limit: int) -> list[CubicSegment | CubicSegments]:
    """The segments as a motion sends them to an Uno: CUBIC_SEGMENTS frames of up to `limit` records."""
    chain, out, index = SpeedChain.at_rest(3), [], 0
    while index < len(segs):
        frame = pack(segs[index:], chain, limit)
        assert frame is not None
        out.append(frame)
        index += len(frame)
    return out


def feed(segs: list[CubicSegment], name: str, seconds: float, dwell: bool = False, runs: int = 0) -> dict:
    """Run segs flow-controlled (with `runs`, in CUBIC_SEGMENTS frames of that many records); with dwell,
    after a segment that moves nothing for 1022 ticks, so that the queue is full before the motion starts
    (as a host starts a job) and the ticks measured serve no bytes but the acks'."""
    WORK.mkdir(parents=True, exist_ok=True)
    if dwell:
        segs = [CubicSegment(n=1022), *segs]
    messages = in_runs(segs, runs) if runs else segs
    frames = b"".join(encode(s, i & 0xFF) for i, s in enumerate(messages))
    path = WORK / f"{name}.feed"
    path.write_bytes(frames)
    stats = WORK / f"{name}.json"
    args = [*avr_sim.harness("uno", None), "--feed", str(path), "--max-cycles", str(int(seconds * F_CPU)),
            "--stats", str(stats)]
    subprocess.run(args, capture_output=True, check=True)
    return avr_sim.Outputs(WORK / f"{name}-t.csv", WORK / f"{name}-e.csv", stats).load_stats()


def clean(st: dict) -> bool:
    f, m = st["feed"], st["motion"]
    return (f["accepted"] == f["frames"] and f["errors"] == 0 and f["alarms"] == 0 and st["wire"]["lost"] == 0
            and m["ticks_missed"] == 0)


def main_loop_cycles(st: dict, segments: int | None = None) -> float:
    """Main-loop cycles per frame, or per segment of `segments`."""
    isr = st["isr"]["timer"]
    return (st["cycles"] - st["sleep_cycles"] - isr["count"] * isr["mean"]) / (segments or st["feed"]["frames"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    subprocess.run(["make", "-C", str(REPO), "-s", "firmware", "harness"], check=True, capture_output=True)
    tick_hz = avr_sim.avr_define("QS_TICK_HZ")
    print(f"cubic segments on the Uno at {tick_hz} Hz ({F_CPU // tick_hz} cycles a tick), simavr, exact cycles")
    chained = encode(CubicSegment(n=500, axes=tuple(CubicAxis(axis=a, jerk=7) for a in range(3))), 1)
    cruise = encode(CubicSegment(n=65535), 1)
    print(f"  wire: a chained 3-axis jerk segment {len(chained)} bytes with framing; a cruise {len(cruise)} bytes "
          f"(up to 65535 ticks, {65535 / tick_hz:.2f} s)")
    rows = [("3 axes in jerk phases", jerk_stream(1000, 12)), ("3 axes accelerating", steady_stream(1000, 8, 20000)),
            ("3 axes steady", steady_stream(1000, 8, 0))]
    print(f"  {'step interrupt':>24} {'ticks':>7} {'mean':>7} {'max':>5}   (cycles, 3 axes stepping / all ticks)")
    for name, segs in rows:
        st = feed(segs, name.replace(" ", "-"), 1.0, dwell=True)
        b3 = st["tick_isr"]["steps3"]
        isr = st["isr"]["timer"]
        print(f"  {name:>24} {b3['count']:>7} {b3['mean']:>7.1f} {b3['max']:>5}   all ticks: mean {isr['mean']:.1f}, "
              f"max {isr['max']}; main loop per segment {main_loop_cycles(st):,.0f}")
    seconds = 0.2 if args.quick else 0.5
    limit = run_limit(avr_sim.avr_define("QS_QUEUE_CAPACITY"))
    for runs, how in ((0, "one CUBIC_SEGMENT a frame"), (limit, f"CUBIC_SEGMENTS of {limit} records")):
        shortest(tick_hz, seconds, runs, how)


def shortest(tick_hz: int, seconds: float, runs: int, how: str) -> None:
    """The shortest cubic segment the board takes cleanly with three axes in jerk phases, by bisection."""
    def count(n: int) -> int:
        return max(20, int(seconds * tick_hz / n))

    lo, hi = 16, 4000  # lo fails, hi passes (checked)
    st = feed(jerk_stream(hi, count(hi)), "rate", seconds * 3 + 0.3, runs=runs)
    if not clean(st):
        print(f"  {how}: even 4000-tick cubic segments are not taken cleanly")
        return
    best = st
    while hi - lo > 4:
        mid = (lo + hi) // 2
        st = feed(jerk_stream(mid, count(mid)), "rate", seconds * 3 + 0.3, runs=runs)
        if clean(st):
            hi, best = mid, st
        else:
            lo = mid
    isr = best["isr"]["timer"]
    per_segment = main_loop_cycles(best, len(jerk_stream(hi, count(hi))))
    print(f"  {how}: shortest cubic segment taken with 3 axes in jerk phases {hi} ticks = "
          f"{tick_hz / hi:,.0f} segments/s (step interrupt mean {isr['mean']:.0f}, max {isr['max']}; main loop "
          f"{per_segment:,.0f} cycles per segment)")

if __name__ == "__main__":
    main()
