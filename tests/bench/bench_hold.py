#!/usr/bin/env python3
"""HOLD figures: how soon a HOLD acts (the jog-release latency) on the real-time emulator, how far a job's
feed hold leaves the line it was on (HOLD_ALONG against each axis braking on its own; quadratic and S-curve
plans), and what a hold
costs the AVR firmware in simavr (cycles with the tick locked out, cycles per hold tick).

    python3 tests/bench/bench_hold.py [--holds N] [--no-avr]

Prints figures only; nothing here is a pass/fail test.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import quadstep.machine.motion as motion_module
from quadstep.config import MachineConfig, load_config
from quadstep.emulator import Emulator
from quadstep.job import Job, load_job
from quadstep.kernel.engine_model import predict_hold
from quadstep.link import Link, hold_async
from quadstep.machine import Machine
from quadstep.machine.along_path import along_path
from quadstep.machine.units import hold_decels
from quadstep.protocol import Hold, HoldDone, HoldDoneAlong, Segment, encode
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove

REPO = Path(__file__).resolve().parents[2]
JOG = Segment(n=N_MAX, axes=(AxisMove(axis=0, direction=1, v0=D // 2, vn=D // 2, r=0),
                             AxisMove(axis=1, direction=-1, v0=D // 4, vn=D // 4, r=0)))
JOG_DECEL = [2000, 2000, 2000, 2000]  # ≈ 300,000 steps/s² at 50 kHz


def first_hold_ns(events: Path, count: int, timeout: float = 5.0) -> int:
    """The monotonic time of the count-th hold's first deceleration tick, from the emulator's events log."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        lines = [line for line in events.read_text().splitlines()[1:] if line.startswith("hold,")]
        if len(lines) >= count:
            return int(lines[count - 1].split(",")[2])
        time.sleep(0.001)
    raise RuntimeError("the emulator logged no hold")


def bench_jog_latency(holds: int) -> None:
    """Jog (two axes cruising, segments streamed as the window allows), then let go: HOLD from the caller's
    thread via hold_async, as a key-release handler would. Latency is from just before the call to the
    emulator's first deceleration tick, both on CLOCK_MONOTONIC."""
    latencies, stops = [], []
    with tempfile.TemporaryDirectory() as tmp:
        events = Path(tmp) / "events.csv"
        with Emulator(extra_args=["--events", str(events)]) as emu, Link.open(emu.url) as link:
            for i in range(holds):
                for _ in range(8):
                    link.send(JOG)
                time.sleep(0.05 + 0.01 * (i % 7))
                sent = time.monotonic_ns()
                future = hold_async(link, JOG_DECEL)
                acted = first_hold_ns(events, i + 1)
                done = future.result(10)
                latencies.append((acted - sent) / 1e6)
                stops.append((done.motion_ticks - done.hold_tick) / link.tick_hz * 1e3)
    latencies.sort()
    p95 = latencies[min(len(latencies) - 1, int(0.95 * len(latencies)))]
    print(f"== HOLD latency, paced emulator, {holds} holds (2-core shared machine; wall-clock, varies with load)")
    print(f"HOLD sent -> first deceleration tick   min {latencies[0]:.2f} ms  median {statistics.median(latencies):.2f} ms"
          f"  p95 {p95:.2f} ms  max {latencies[-1]:.2f} ms")
    print(f"deceleration to rest (decel 2000 = 298,000 steps/s² at 50 kHz, from 25,000 steps/s)"
          f"  {statistics.median(stops):.1f} ms")
    print("for comparison: GRBL 1.1 jog cancel, 0.4-0.9 s typical (its jogging guide)")


def off_the_line(position: tuple[int, ...], end: tuple[int, ...]) -> float:
    """Steps from `position` to the line from the origin to `end`, in the X Y plane."""
    return abs(position[0] * end[1] - position[1] * end[0]) / (end[0] ** 2 + end[1] ** 2) ** 0.5


def bench_feed_hold_path(holds: int) -> None:
    """Feed holds at spread moments of a 3:1 diagonal at 40 mm/s (router-uno: 400 steps/mm, 500 mm/s²):
    where each came to rest, in steps from the line; beside it, where each axis braking at its own
    deceleration from the same hold tick would have (engine_model, exact)."""
    config = load_config(REPO / "examples" / "router-uno.toml")
    corner = config.to_steps((30.0, 10.0, 0.0))
    along: list[float] = []
    apart: list[float] = []
    fallbacks = 0
    for k, job, done in diagonal_holds(config, holds):
        fallbacks += not isinstance(done, HoldDoneAlong)
        own = predict_hold(list(job.plan.segments.segments()), done.hold_tick, hold_decels(config), axis_count=3)
        along.append(off_the_line(tuple(done.position), corner))
        apart.append(off_the_line(tuple(own.positions), corner))
    print(f"== a feed hold on a 3:1 diagonal at 40 mm/s (router-uno), {holds} holds from 0.1 to 0.7 s in")
    print(f"steps off the line at rest: HOLD_ALONG median {statistics.median(along):.2f}, max {max(along):.2f}"
          f" ({holds - fallbacks} of {holds} took the path's decelerations); each axis on its own (same hold"
          f" tick) median {statistics.median(apart):.1f}, max {max(apart):.1f}")


def bench_feed_hold_scurve(holds: int) -> None:
    """The same diagonal planned as S-curves (max_jerk 20,000 mm/s³): where each hold came to rest, in steps
    from the line, with HOLD_ALONG and with each axis braking on its own (no host model predicts a hold
    from a cubic segment: those holds are run too, at the same moments, every HOLD a plain one)."""
    config = load_config(REPO / "examples" / "router-uno.toml")
    config = config.model_copy(update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0})
                                                     for a in config.axes)})
    corner = config.to_steps((30.0, 10.0, 0.0))
    off: dict[str, list[float]] = {"along": [], "own": []}
    fallbacks = 0
    for label, rest in off.items():
        motion_module.along_path = along_path if label == "along" else lambda *args: None
        for _, _, done in diagonal_holds(config, holds):
            fallbacks += label == "along" and not isinstance(done, HoldDoneAlong)
            rest.append(off_the_line(tuple(done.position), corner))
    motion_module.along_path = along_path
    print(f"== the same diagonal as S-curves (max_jerk 20,000 mm/s³), {holds} holds from 0.1 to 0.7 s in")
    print(f"steps off the line at rest: HOLD_ALONG median {statistics.median(off['along']):.2f},"
          f" max {max(off['along']):.2f} ({holds - fallbacks} of {holds} took the path's decelerations);"
          f" each axis on its own median {statistics.median(off['own']):.1f}, max {max(off['own']):.1f}")


def diagonal_holds(config: MachineConfig, holds: int) -> Iterator[tuple[int, Job, HoldDone]]:
    """A feed hold at each of `holds` spread moments of the diagonal, each on a fresh emulator: the job and
    the hold's HOLD_DONE."""
    with tempfile.TemporaryDirectory() as work:
        path = Path(work) / "diagonal.gcode"
        path.write_text("G21 G90 F2400\nG1 X30 Y10\n")
        for k in range(holds):
            emu = Emulator(tick_hz=config.tick_hz, axes=3, queue=14).start()
            try:
                with Link.open(emu.url) as link:
                    machine = Machine(link, config)
                    job = load_job(path, config, machine.position)
                    run = machine.run_job(job.plan, job.program)
                    time.sleep(0.1 + 0.6 * k / max(1, holds - 1))
                    run.feed_hold()
                    while not run.held:
                        time.sleep(0.005)
                    done = link.last_report(HoldDone)
                    assert done is not None
                    yield k, job, done
                    run.halt()
            finally:
                emu.stop()


def bench_avr() -> None:
    sys.path.insert(0, str(REPO / "tests" / "simavr"))
    import avr_sim

    avr_sim.build()
    print("== HOLD on the AVR firmware in simavr (16 MHz; exact cycle counts)")
    for board, axes in (("uno", 3), ("mega", 4)):
        cruise = Segment(n=N_MAX, axes=tuple(AxisMove(axis=a, direction=1, v0=D, vn=D, r=0) for a in range(axes)))
        decels = tuple([500] * axes + [0] * (4 - axes))
        with tempfile.TemporaryDirectory() as tmp:
            out = avr_sim.Outputs.in_dir(Path(tmp), board)
            data = b"\x00" + b"".join(encode(cruise, i) for i in range(12)) + encode(Hold(decel=decels), 12)  # type: ignore[arg-type]
            (Path(tmp) / "in.bin").write_bytes(data)
            subprocess.run([*avr_sim.harness(board), "--input", str(Path(tmp) / "in.bin"),
                            "--max-cycles", str(3 * avr_sim.F_CPU), *out.args()],
                           check=True, capture_output=True)
            stats = json.loads(out.stats.read_text())
        bins = {k: v for k, v in stats["tick_isr"].items() if v["count"] and k != "idle"}
        tick = stats["tick_cycles"]
        print(f"{board}: {axes} axes at full speed, then HOLD at decel 500; tick period {tick} cycles")
        print(f"  longest stretch with the tick locked out: {stats['irq_off']['max']} cycles"
              f" ({stats['irq_off']['from']}: beginning the hold)")
        for name, b in bins.items():
            print(f"  step interrupt, {name:7} {b['count']:6} ticks  mean {b['mean']:6.1f}  max {b['max']} cycles")
        size = subprocess.run(["avr-size", str(avr_sim.elf_path(board))], capture_output=True, text=True).stdout
        print("  " + size.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--holds", type=int, default=20)
    parser.add_argument("--no-avr", action="store_true")
    args = parser.parse_args()
    bench_jog_latency(args.holds)
    bench_feed_hold_path(args.holds)
    bench_feed_hold_scurve(args.holds)
    if not args.no_avr:
        bench_avr()


if __name__ == "__main__":
    main()
