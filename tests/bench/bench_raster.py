"""Raster benchmark: a grayscale image sent as RASTER lines on the real-time emulator (3 axes, 32 kHz,
an Uno's queue of 14), at 100 mm/s with 0.1 mm pixels and faster: pixels a second, bytes on the wire a
pixel, retransmits, underruns (a STARVED board) and how far each power switch is from its boundary's
tick. Nothing is asserted.

Then a LightBurn-style raster file (a `G1 X… S…` a pixel) streamed through `quadstep grbl`, against
`quadstep run` of it. Then the real Mega build and the Uno's laser build (`quadstep flash --board uno-laser`: RASTER with a
ring of 128 powers in the room of the cubic segments) in simavr, fed RASTER lines as fast as flow
control allows: the pixel rate each keeps up with. The Uno's own build has no RASTER (no flash left for
it: capability bit 14 clear, rasters go out as ordinary moves there); the bench harness has no GRBL in
simavr (tests/bench/bench_avr.py quotes GRBL's published figures).

    python3 tests/bench/bench_raster.py
"""

from __future__ import annotations

import random
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))

import numpy as np  # noqa: E402

from quadstep.config import load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.kernel.engine_model import predict
from quadstep.link import Link  # noqa: E402
from quadstep.machine import Machine  # noqa: E402
from quadstep.planner.raster import RasterImage, plan_raster  # noqa: E402
from quadstep.protocol.raster import RasterLine  # noqa: E402

CONFIG = load_config(REPO / "examples" / "laser-uno.toml")


def run(pixel_mm: float, feed: float, rows: int, columns: int) -> None:
    rng = random.Random(3)
    image = RasterImage(
        rows=[[rng.randrange(256) for _ in range(columns)] for _ in range(rows)],
        x_mm=20,
        y_mm=20,
        pixel_mm=pixel_mm,
        row_mm=0.1,
        feed_mm_s=feed,
    )
    pixels = rows * columns
    with tempfile.TemporaryDirectory() as tmp:
        trace, outputs = Path(tmp) / "trace.csv", Path(tmp) / "outputs.csv"
        args = ["--outputs", str(outputs)]
        with Emulator(
            tick_hz=CONFIG.tick_hz, axes=3, queue=14, trace=trace, extra_args=args
        ) as emu:
            with Link.open(emu.url) as link:
                machine = Machine(link, CONFIG)
                plan = plan_raster(image, CONFIG, tuple(machine.position))
                before = dict(link.stats.as_dict())
                began = time.monotonic()
                end = machine.run_job(plan).wait()
                seconds = time.monotonic() - began
                after = link.stats.as_dict()
                machine.close()
        segments = list(plan.segments.segments())
        lines = [s for s in segments if isinstance(s, RasterLine)]
        burn_ticks = sum(s.n for s in lines)
        steps = predict(segments, list(plan.start), axis_count=3).steps
        exact = np.array_equal(
            np.loadtxt(trace, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2), steps
        )
    frames = after["frames_sent"] - before["frames_sent"]
    resent = after["retransmits"] - before["retransmits"]
    sent = after["bytes_sent"] - before["bytes_sent"]
    raster_bytes = sum(len(s.raster.power) + 14 for s in lines)  # payload, header, framing
    print(
        f"  {pixel_mm:g} mm pixels at {feed:g} mm/s: {feed / pixel_mm:,.0f} pixels/s while burning "
        f"({pixels} pixels, {len(lines)} RASTER lines, {burn_ticks / CONFIG.tick_hz:.2f} s burning of "
        f"{seconds:.2f} s); ended {end.ended_by if end else None}; steps as predicted: {exact}"
    )
    print(
        f"    wire: {sent / pixels:.2f} B/pixel in all ({raster_bytes / pixels:.2f} in RASTER frames), "
        f"{frames} frames, {resent} retransmits ({100 * resent / max(1, frames):.2f} %)"
    )


def board(
    name: str, tick_hz: int, v: int, steps_per_pixel: int, lines: int = 300, pixels: int = 32
) -> None:
    """A real board build in simavr, fed RASTER lines as fast as flow control allows: lines of
    `pixels`, as many as its queue holds fitting its ring (the Mega: 32 of 32 in 1,024 powers; the
    Uno's laser build: 12 of 10 in 128), as the host paces them."""
    sys.path.insert(0, str(REPO / "tests" / "simavr"))
    import subprocess

    from avr_sim import Outputs, build, harness
    from quadstep.protocol import Output, Segment, encode
    from quadstep.kernel.motion import AxisMove
    from quadstep.protocol import Outputs as OutputsMessage
    from quadstep.protocol.raster import Raster

    build()
    rng = random.Random(1)
    n = -(-pixels * steps_per_pixel * 4096 // v)
    ramp = 400
    up = Segment(n=ramp, axes=(AxisMove(axis=0, direction=1, v0=0, vn=v, r=0),))
    down = Segment(n=ramp, axes=(AxisMove(axis=0, direction=1, v0=v, vn=0, r=0),))
    pitch = steps_per_pixel * 256
    messages = [OutputsMessage(outputs=Output.ON, power=0), up]
    messages += [
        Raster(
            n=n,
            axes=1,
            pixel=0,
            phase=pitch,
            pitch=pitch,
            power=tuple(rng.randrange(256) for _ in range(pixels)),
        )
        for _ in range(lines)
    ]
    messages += [down, OutputsMessage(outputs=0, power=0)]
    with tempfile.TemporaryDirectory() as tmp:
        outputs = Outputs.in_dir(Path(tmp))
        feed = Path(tmp) / "frames.feed"
        feed.write_bytes(b"".join(encode(m, i % 256) for i, m in enumerate(messages)))
        subprocess.run(
            [
                *harness(name),
                "--feed",
                str(feed),
                "--max-cycles",
                str(60 * 16_000_000),
                *outputs.args(),
            ],
            capture_output=True,
            timeout=600,
            check=True,
        )
        stats = outputs.load_stats()
    rate = tick_hz * v / 4096 / steps_per_pixel
    f, m = stats["feed"], stats["motion"]
    print(
        f"  {rate:,.0f} pixels/s ({lines * pixels} pixels, {steps_per_pixel} step(s) a pixel): "
        f"{f['accepted']}/{f['frames']} frames taken, {f['gap']} gaps, {f['queue_full']} queue full, "
        f"{f['holds']} holds (an underrun), ticks missed {m['ticks_missed']}, ended in state {m['state']}; "
        f"step interrupt mean {stats['isr']['timer']['mean']:.0f}, longest {stats['isr']['timer']['max']} cycles"
    )


def pixel_timing(name: str) -> None:
    """Where each pixel's power begins on a real board build, against the step that crosses its boundary
    (tests/simavr/avr_raster_pixels.py: 10 pixels of 50 steps at half a step a tick)."""
    sys.path.insert(0, str(REPO / "tests" / "simavr"))
    from avr_raster_pixels import pixel_starts, run_pixels
    from avr_sim import build

    build()
    with tempfile.TemporaryDirectory() as tmp:
        run = run_pixels(name, Path(tmp))
    starts = pixel_starts(run)
    tick = run.stats["tick_cycles"]
    inner = [s for i, s in enumerate(starts) if i % 5]
    print(
        f"  {name}: each pixel's PWM period begins {-max(inner)}..{-min(inner)} cycles before the step that "
        f"crosses its boundary (a tick is {tick}; a line's first pixel {-max(starts[::5])}..{-min(starts[::5])} "
        f"before its first step); step interrupt mean {run.stats['isr']['timer']['mean']:.0f}, longest "
        f"{run.stats['isr']['timer']['max']} cycles"
    )


def front_door(rows: int, pixels: int, feed_mm_min: float) -> None:
    """The file streamed through `quadstep grbl` by character counting, against `quadstep run` of it:
    the wall time from the first line to rest, jobs, frames, retransmits, the board running dry."""
    sys.path.insert(0, str(REPO / "tests" / "helpers"))
    from grbl_client import GrblClient, report_fields
    from grbl_door import serving
    from laser_raster import raster_gcode, record_jobs

    from quadstep.job import load_job

    lines = raster_gcode(rows, pixels, feed_mm_min)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "raster.nc"
        path.write_text("\n".join(lines) + "\n")
        for way in ("grbl", "run"):
            with Emulator(tick_hz=CONFIG.tick_hz, axes=3, queue=14) as emu, Link.open(emu.url) as link:
                machine = Machine(link, CONFIG)
                jobs = record_jobs(machine)
                before = dict(link.stats.as_dict())
                began = time.monotonic()
                if way == "grbl":
                    with serving(machine) as pty, GrblClient(str(pty.path)) as grbl:
                        grbl.wait_banner()
                        answers = grbl.stream_counting(lines)
                        grbl.wait_status(lambda report: report_fields(report)["state"] == "Idle", 300)
                    assert answers == ["ok"] * len(answers)
                else:
                    job = load_job(path, CONFIG, tuple(machine.position))
                    machine.run_job(job.plan, job.program).wait()
                seconds = time.monotonic() - began
                after = link.stats.as_dict()
                machine.close()
            delta = {k: after[k] - before.get(k, 0) for k in ("frames_sent", "retransmits", "bytes_sent")}
            dry = sum(job.states.starvations for job in jobs)
            print(
                f"  {way:4}: {seconds:.2f} s, {len(jobs)} job(s), {delta['frames_sent']} frames, "
                f"{delta['retransmits']} retransmits, {delta['bytes_sent'] / (rows * pixels):.2f} B/pixel, "
                f"ran dry {dry} times"
            )


def main() -> None:
    print("== RASTER on the real-time emulator (3 axes, 32 kHz, queue 14), laser-uno.toml")
    run(0.1, 100.0, 8, 400)
    run(0.05, 200.0, 8, 800)
    run(0.025, 200.0, 8, 1600)
    run(0.0125, 200.0, 4, 3200)
    print("  the Uno's UART at 500 kbaud carries 50,000 B/s: at 1.7 B/pixel about 29,000 pixels/s")
    print("== a LightBurn-style raster (12 rows of 300 0.1 mm pixels at 100 mm/s) through quadstep grbl")
    front_door(12, 300, 6000)
    print("== RASTER on the real Mega build in simavr (25 kHz)")
    board("mega", 25000, 2048, 1)
    board("mega", 25000, 4096, 1)
    print("== RASTER on the Uno's laser build in simavr (32 kHz; the Uno's own build has no RASTER)")
    for v, pixels in ((1280, 10), (2048, 10), (2560, 10), (1280, 32), (4096, 32)):
        board("uno-laser", 32000, v, 1, lines=9600 // pixels, pixels=pixels)
    print("== where a pixel of a PWM period or more begins on the board (simavr: the tick restarts the period there)")
    pixel_timing("uno-laser")
    pixel_timing("mega")


if __name__ == "__main__":
    main()
