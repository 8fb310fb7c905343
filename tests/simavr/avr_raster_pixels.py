"""Two RASTER lines of five 50-step pixels between ramps, run on a real board build in simavr with its
output pins recorded, and where each pixel's power begins against the step that crosses its boundary.
Shared by tests/simavr/test_avr_raster.py and tests/bench/bench_raster.py."""

from __future__ import annotations

import csv
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from avr_sim import Outputs, harness
from quadstep.kernel.engine_model import predict
from quadstep.kernel.motion import AxisMove
from quadstep.protocol import Output, Outputs as OutputsMessage, Segment, encode
from quadstep.protocol.raster import Raster, RasterLine

V = 2048  # half a step a tick: a pixel of 50 steps lasts 100 ticks, 4 ms at the Mega's 25 kHz, about 4 periods
AXES = {"mega": 4, "uno-laser": 3}
POWERS = [[30, 200, 90, 250, 10], [120, 5, 220, 60, 180]]
PIXEL_STEPS = 50
PWM_STEP = 64  # cycles per count of the PWM's timer: high (power + 1) * 64 cycles of each period


def line(powers: list[int]) -> RasterLine:
    """1,000 ticks at V (500 steps), five pixels of 50 steps, the first one from the start (the last one to
    the end)."""
    pitch = PIXEL_STEPS * 256
    raster = Raster(n=1000, axes=0x01, pixel=0, phase=pitch, pitch=pitch, power=tuple(powers))
    return RasterLine(n=1000, axes=(AxisMove(axis=0, direction=1, v0=V, vn=V, r=0),), raster=raster)


@dataclass
class PixelRun:
    stats: dict
    pwm: list[tuple[int, int]]  # (cycle, level) of the laser's PWM pin
    x_steps: list[int]  # cycles of X's rising step edges
    trace: np.ndarray
    segments: list
    axis_count: int


def run_pixels(board: str, directory: Path) -> PixelRun:
    ramp_up = Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=0, vn=V, r=0),))
    ramp_down = Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=V, vn=0, r=0),))
    lines = [line(p) for p in POWERS]
    messages = [
        OutputsMessage(outputs=Output.ON, power=0),
        ramp_up,
        *(x.raster for x in lines),
        ramp_down,
        OutputsMessage(outputs=0, power=0),
        Segment(n=500, axes=()),
    ]
    outputs = Outputs.in_dir(directory)
    pins = directory / "pins.csv"
    feed = outputs.stats.with_suffix(".feed")
    feed.write_bytes(b"".join(encode(m, i) for i, m in enumerate(messages)))
    args = [*harness(board), "--feed", str(feed), "--max-cycles", str(2 * 16_000_000), "--outputs", str(pins),
            *outputs.args()]
    result = subprocess.run(args, capture_output=True, timeout=120)
    if result.returncode != 0:
        raise RuntimeError(result.stderr.decode(errors="replace"))
    with pins.open() as f:
        pwm = [(int(r["cycle"]), int(r["level"])) for r in csv.DictReader(f) if r["pin"] == "pwm"]
    x_steps = sorted(c for c, pin, axis, level in outputs.load_edges() if pin == "step" and axis == 0 and level)
    segments = [ramp_up, *lines, ramp_down, Segment(n=500, axes=())]
    return PixelRun(outputs.load_stats(), pwm, x_steps, outputs.load_trace(), segments, AXES[board])


def pixel_starts(run: PixelRun) -> list[int]:
    """For each pixel, in cycles from the rising edge of the step that crosses its boundary (a line's first
    pixel: from its first step), where the PWM period showing its power begins: the one fall of the pin
    (power + 1) * 64 cycles after a start within two ticks of that edge. Raises if there is none or more."""
    tick = run.stats["tick_cycles"]
    falls = [cycle for cycle, level in run.pwm if not level]
    ends = np.cumsum([s.n for s in run.segments])
    x_in_segment = [0] * len(run.segments)
    for t, axis, _ in predict(run.segments, [0] * run.axis_count, axis_count=run.axis_count).steps:
        if axis == 0:
            x_in_segment[int(np.searchsorted(ends, t))] += 1
    starts = []
    for j, powers in enumerate(POWERS):
        before = sum(x_in_segment[: j + 1])  # X steps before the line
        for k, power in enumerate(powers):
            step_cycle = run.x_steps[before + max(PIXEL_STEPS * k, 1) - 1]
            high = (power + 1) * PWM_STEP
            begun = [f - high - step_cycle for f in falls if abs(f - high - step_cycle) <= 2 * tick]
            if len(begun) != 1:
                raise AssertionError(f"line {j} pixel {k} (power {power}): period starts {begun} near {step_cycle}")
            starts.append(begun[0])
    return starts


@dataclass
class HeldLine:
    stats: dict
    pwm: list[tuple[int, int]]
    hold_cycle: int  # the cycle of the first step at or after the hold's first decelerating tick
    tick: int


def run_hold_in_line(board: str, directory: Path) -> HeldLine:
    """A line of five 100-tick pixels, and a HOLD that the board takes in its middle (after `pad` empty
    frames on a line left free-running: no flow control), at 8,000 / 2^24 step per tick² (about 1,000
    ticks to rest); the hold's first decelerating tick from its HOLD_DONE."""
    from avr_sim import run_input
    from quadstep.protocol import Decoder, Hold
    from quadstep.protocol.messages import HoldDone

    ramp_up = Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=0, vn=V, r=0),))
    messages = [OutputsMessage(outputs=Output.ON, power=0), ramp_up, line([100, 180, 60, 220, 140]).raster]
    job = b"\x00" + b"".join(encode(m, i) for i, m in enumerate(messages))
    hold = Hold(decel=(8000,) * AXES[board] + (0,) * (4 - AXES[board]))  # type: ignore[arg-type]
    outputs = Outputs.in_dir(directory)
    pins = directory / "pins.csv"
    replies = directory / "replies.bin"
    data = job + b"\x00" * 900 + encode(hold, len(messages))  # 18 ms of the line: the line runs
    stats = run_input(data, outputs, replies, board=board, max_cycles=16_000_000 // 5, until_idle=False,
                      extra_args=["--outputs", str(pins)])
    with pins.open() as f:
        pwm = [(int(r["cycle"]), int(r["level"])) for r in csv.DictReader(f) if r["pin"] == "pwm"]
    done = [m for m in (getattr(i, "message", None) for i in Decoder("to_host", axis_count=AXES[board]).feed(
        replies.read_bytes())) if isinstance(m, HoldDone)]
    if not done:
        raise AssertionError("no HOLD_DONE")
    trace = outputs.load_trace()
    x_steps = sorted(c for c, pin, axis, level in outputs.load_edges() if pin == "step" and axis == 0 and level)
    x_ticks = [int(t) for t, axis, _ in trace if axis == 0]
    first = next(i for i, t in enumerate(x_ticks) if t > done[0].hold_tick)
    return HeldLine(stats, pwm, x_steps[first], stats["tick_cycles"])
