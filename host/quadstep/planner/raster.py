"""Laser rasters: rows of pixels along X, each row a ramp to speed, a run at that speed sent as
RASTER lines (a power per pixel, switched at the step of each boundary: PROTOCOL.md §5.2), and a
ramp to rest; between rows a rapid, laser dark, to the next row's run-in.

Every position is exact: the pixel boundaries are the steps the image's mm give (rounded once, as
every target is), and the host knows every step of the motion from the segments it makes here.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from dataclasses import dataclass, field
from itertools import accumulate

from ..config import MachineConfig
from ..kernel.fixed import N_MAX, D
from ..kernel.motion import AxisMove, Direction
from ..protocol import Output, Outputs
from ..protocol.raster import PIXELS_MAX, STEP, Raster, RasterLine
from ..protocol.segment import Segment
from .plan import Plan, plan_program
from .program import JobError, LinearMove, Program
from .stream import Stream

TWO_D = 2 * D
RAMP_FRACTION = 0.8  # of the X axis's acceleration, as the planner leaves a margin too
RUN_IN_MARGIN = 2  # steps between the end of the ramp and the first boundary


@dataclass(frozen=True)
class RasterImage:
    """Rows of powers (0 … 255, the duty's high byte) over pixels `pixel_mm` wide, the first row's
    first pixel starting at machine (`x_mm`, `y_mm`), rows `row_mm` apart (+Y)."""

    rows: list[list[int]]
    x_mm: float
    y_mm: float
    pixel_mm: float
    row_mm: float
    feed_mm_s: float
    bidirectional: bool = True


@dataclass
class _Axis:
    """An axis's exact state: its step position and the ideal ahead of it in 1/8192 step."""

    position: int
    ahead: int = 0

    def run(self, direction: Direction, v0: int, vn: int, n: int) -> AxisMove:
        """One segment of this axis; the state moves on past it."""
        r = direction * self.ahead
        travel = r + (v0 + vn) * n
        steps = (travel + D) // TWO_D
        self.position += direction * steps
        self.ahead = direction * (travel - TWO_D * steps)
        return AxisMove(axis=0, direction=direction, v0=v0, vn=vn, r=r)


@dataclass
class _Builder:
    config: MachineConfig
    segments: list[Segment] = field(default_factory=list)

    def travel(self, start: tuple[int, ...], target: tuple[int, ...]) -> tuple[int, ...]:
        """A rapid to `target` (steps), laser dark; returns where it ends."""
        if start == target:
            return start
        move = LinearMove(line=0, target=self.config.to_mm(target), feed=None)
        plan = plan_program(Program(items=[move]), self.config, start)
        self.segments += plan.quadratic_segments()
        return plan.end


def _ramp_knots(v: int, accel: float) -> list[tuple[int, int]]:
    """(ticks, speed at its end) of the segments that take X from rest to `v` at most at `accel`
    (1/4096 step per tick²)."""
    ticks = max(1, math.ceil(v / accel))
    pieces = math.ceil(ticks / N_MAX)
    out, done = [], 0
    for j in range(1, pieces + 1):
        end = ticks * j // pieces
        out.append((end - done, round(v * j / pieces)))
        done = end
    return out


def _fit(offsets: list[int], ks: list[int], pitch: int) -> tuple[int, int] | None:
    """(phase, pitch) near `pitch` (1/256 step) that puts grid point ks[i] at offsets[i]:
    ⌊(phase + (k − 1)·pitch) / 256⌋ = offset, phase in 256 … pitch."""
    for p in sorted(range(max(STEP, pitch - 6), pitch + 7), key=lambda q: abs(q - pitch)):
        lo, hi = STEP, p
        for o, k in zip(offsets, ks):
            lo = max(lo, STEP * o - (k - 1) * p)
            hi = min(hi, STEP * o + STEP - 1 - (k - 1) * p)
        if lo <= hi and p <= 0xFFFF:
            return lo, p
    return None


def _cruise(
    x: _Axis, direction: Direction, v: int, changes: list[tuple[int, int]], end: int, pitch: int
) -> list[RasterLine]:
    """RASTER lines at speed `v` from where `x` is: `changes` (absolute step, power from there),
    in the order the axis meets them; the run ends at the step that reaches `end`."""
    r0, start = direction * x.ahead, x.position

    def steps(t: int) -> int:
        return (r0 + 2 * v * t + D) // TWO_D

    def tick_of(offset: int) -> int:
        return max(0, -(-(TWO_D * offset - D - r0) // (2 * v)))

    rel = [(direction * (s - start), p) for s, p in changes]
    total = tick_of(direction * (end - start))
    lines: list[RasterLine] = []
    t, power, i = 0, 0, 0
    while t < total:
        s0 = steps(t)
        while i < len(rel) and rel[i][0] <= s0:
            power = rel[i][1]
            i += 1
        offsets: list[int] = []
        ks: list[int] = []
        powers = [power]
        fit: tuple[int, int] = (STEP, STEP)
        stop = min(total, t + N_MAX)
        j = i
        while j < len(rel):
            o = rel[j][0] - s0
            k = (
                (ks[-1] + max(1, round((o - offsets[-1]) * STEP / pitch)))
                if ks
                else (1 + max(0, -(-(STEP * o - pitch) // pitch)))
            )
            found = _fit([*offsets, o], [*ks, k], pitch) if k < PIXELS_MAX else None
            if found is None or tick_of(rel[j][0]) > stop:
                stop = min(stop, max(t + 1, tick_of(s0 + o) - 1))
                break
            powers += [powers[-1]] * (k - len(powers)) + [rel[j][1]]
            offsets.append(o)
            ks.append(k)
            fit = found
            j += 1
        n = stop - t
        ahead = r0 + 2 * v * t - TWO_D * s0
        raster = Raster(
            n=n,
            axes=0x01 | (0x10 if direction < 0 else 0),
            pixel=0,
            phase=fit[0],
            pitch=fit[1],
            power=tuple(powers),
        )
        axis = AxisMove(axis=0, direction=direction, v0=v, vn=v, r=ahead)
        lines.append(RasterLine(n=n, axes=(axis,), raster=raster))
        i = j
        power = powers[-1]
        t = stop
    x.ahead = direction * (r0 + 2 * v * total - TWO_D * steps(total))
    x.position = start + direction * steps(total)
    return lines


@dataclass(frozen=True)
class RasterRow:
    """One row: its pixels' edges along X (mm, in the order it burns them), a power (0 … 255)
    over each pixel, where the other axes stand (`at_mm`), and its feed."""

    edges_mm: list[float]
    powers: list[int]
    at_mm: tuple[float, ...]
    feed_mm_s: float


def row_segments(
    row: RasterRow, config: MachineConfig, start: tuple[int, ...]
) -> tuple[list[Segment], tuple[int, ...], list[int]]:
    """A rapid to the row's run-in, the ramp to its feed, its RASTER lines, the ramp to rest; where
    the machine rests after it; and for each pixel the segments up to the one that reaches its
    end."""
    ax = config.axes[0]
    tick = config.tick_hz
    # the feed, within X's max_speed as the planner keeps every feed
    v = min(D, round(min(row.feed_mm_s, ax.max_speed) * ax.steps_per_mm / tick * D))
    if v < 1:
        raise JobError(f"raster feed {row.feed_mm_s:g} mm/s: under one X step in {D} ticks")
    edges = [ax.to_steps(x) for x in row.edges_mm]
    gaps = [abs(b - a) for a, b in zip(edges, edges[1:]) if b != a]
    if not gaps:
        raise JobError("a raster row of pixels under one X step")
    direction: Direction = 1 if edges[-1] > edges[0] else -1
    knots = _ramp_knots(v, RAMP_FRACTION * ax.max_accel * ax.steps_per_mm / tick**2 * D)
    starts = [0] + [k[1] for k in knots]
    ramp_steps = sum(n * (a + b) for (n, b), a in zip(knots, starts)) // TWO_D
    overscan = round(config.spindle.overscan_mm * ax.steps_per_mm)
    build = _Builder(config)
    run_in = edges[0] - direction * (ramp_steps + RUN_IN_MARGIN + overscan)
    rest = config.to_steps(row.at_mm)
    position = build.travel(tuple(start), (run_in, *rest[1:]))
    x = _Axis(position[0])
    build.segments += _ramp(x, direction, knots, up=True)
    changes = [*zip(edges, row.powers), (edges[-1], 0)]
    end = edges[-1] + direction * (1 + overscan)
    r0, begin, base = direction * x.ahead, x.position, len(build.segments)
    lines = _cruise(x, direction, v, changes, end, min(gaps) * STEP)
    build.segments += lines
    build.segments += _ramp(x, direction, knots, up=False)
    # each pixel's end: the segments up to the line in which X reaches it
    line_ends = list(accumulate(line.n for line in lines))  # ticks into the run
    ends = [
        base
        + bisect_left(line_ends, max(1, -(-(TWO_D * direction * (e - begin) - D - r0) // (2 * v))))
        + 1
        for e in edges[1:]
    ]
    return build.segments, (x.position, *position[1:]), ends


def plan_raster(image: RasterImage, config: MachineConfig, start: tuple[int, ...]) -> Plan:
    """The whole image as a plan the machine streams: OUTPUTS on at power 0 first (the pixels
    give the power), everything off at the end."""
    segments: list[Segment] = []
    position = tuple(start)
    for number, powers in enumerate(image.rows):
        if not powers:
            continue
        edges = [image.x_mm + j * image.pixel_mm for j in range(len(powers) + 1)]
        if image.bidirectional and number % 2:
            edges, powers = edges[::-1], powers[::-1]
        at = (image.x_mm, image.y_mm + number * image.row_mm, *config.to_mm(position)[2:])
        row = RasterRow(edges_mm=edges, powers=powers, at_mm=at, feed_mm_s=image.feed_mm_s)
        more, position, _ = row_segments(row, config, position)
        segments += more
    stream = Stream(base=list(segments), axes=len(config.axes))
    for i in range(len(segments)):
        stream.add_base(i)
    on = Outputs(outputs=int(Output.ON), power=0)
    return Plan(
        config=config,
        segments=stream,
        start=tuple(start),
        end=position,
        outputs=[(0, 0, on), (len(stream), 0, Outputs(outputs=0, power=0))],
        moves=len(image.rows),
    )


def _ramp(x: _Axis, direction: Direction, knots: list[tuple[int, int]], up: bool) -> list[Segment]:
    """X from rest to the top speed (`up`), or back to rest, along `knots`."""
    speeds = [0] + [k[1] for k in knots]
    ticks = [k[0] for k in knots]
    if not up:
        speeds.reverse()
        ticks.reverse()
    out = []
    for j, n in enumerate(ticks):
        out.append(Segment(n=n, axes=(x.run(direction, speeds[j], speeds[j + 1], n),)))
    return out
