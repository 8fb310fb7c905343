"""The compensation stage: a planned stream with every reversal's take-up inside it
(docs/BACKLASH.md).

After planning, per axis with a backlash: where the axis reverses (against the side its carriage was
last pushed to), the motor makes the take-up — seed 004's ramp, within the axis's acceleration and
jerk — while the path goes on. Where it goes:

- `gap`: inside the axis's own pause between its last step one way and its first step the other (a
pocket's
  stepover, a circle's quadrant, where the axis's ideal lingers within half a step): no path error
  at all;
- `rest`: where every axis is at rest anyway (the stream's start, a stop, a pause): added ticks, no
error;
- `around` (or `after`, by the configuration): superposed on the motion, centred on the reversal,
with the
  acceleration left over by the path's own.

The segments a take-up touches (a window) become cubic segments that follow the planned ideal to the
quantum plus the ramp (fit.py); every other segment goes out as planned. The positions reported
exclude the take-ups (band.py); `takeups` says where each is, for plots and checks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np

from ..config import MachineConfig
from ..kernel.cubic_chain import CubicChain
from ..kernel.engine_model import predict
from ..kernel.motion import AxisMove
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from ..protocol.segment import Segment
from .band import Band
from .base import BaseStream, Poly
from .fit import FitError, Span, fit_window
from .takeup import Ramp, design

JERK_TIME = 0.005  # s: without a configured jerk, the take-up reaches its acceleration in this time


@dataclass(frozen=True)
class TakeUp:
    """One take-up as streamed: axis, first motion tick (from the stream's start), length, steps,
    where."""

    axis: int
    start: int
    ticks: int
    steps: int
    kind: str  # gap, rest, around, after
    peak_accel: float  # mm/s²
    line: int
    planned: int  # the motion tick of the plan (without take-ups) where it begins


@dataclass(frozen=True)
class Window:
    """Segments of the stream that are cubic because a take-up runs in them."""

    first: int  # index of its first segment in the stream
    count: int
    start: int  # motion tick it begins at
    ticks: int
    band: Band  # the band as the window begins
    band_after: Band
    chain: CubicChain  # the firmware's chain as it begins
    motor: tuple[int, ...]  # the motors as it begins, from the stream's start


@dataclass
class Compensated:
    """The stream as sent, its take-ups, and the band before (every moving axis's side known), after
    and inside."""

    stream: Stream
    band_start: Band
    band_end: Band
    takeups: list[TakeUp] = field(default_factory=list)
    windows: list[Window] = field(default_factory=list)
    pauses: list[tuple[int, int]] = field(default_factory=list)
    added_ticks: int = 0
    # the firmware's chain where the stream begins, when it goes on from another (machine/rebase.py)
    entry: CubicChain | None = None

    def band_at(self, tick: int, moved: Sequence[int] | None = None) -> Band:
        """The band after `tick` motion ticks of the stream — and, given `moved` (each motor's steps
        from the stream's start to where it rests), after a stop there: a hold's deceleration goes
        on one way."""
        band = self.band_start
        for window in self.windows:
            if tick < window.start:
                break
            if tick >= window.start + window.ticks:
                band = window.band_after
                continue
            made = predict(
                self.stream.segments(window.first, window.first + window.count),
                axis_count=self.stream.axis_count,
                chain=window.chain.copy(),
            )
            rows = made.steps[made.steps[:, 0] <= tick - window.start]
            band = window.band
            motor = list(window.motor)
            for axis in range(len(band.axes)):
                steps = rows[rows[:, 1] == axis, 2]
                band = band.with_axis(axis, band.axes[axis].moved(int(s) for s in steps))
                motor[axis] += int(steps.sum())
            if moved is not None:
                for axis in range(len(band.axes)):
                    band = band.with_axis(axis, band.axes[axis].monotone(moved[axis] - motor[axis]))
            return band
        return band


@dataclass
class _Placed:
    axis: int
    ramp: Ramp
    kind: str
    at: int  # base tick (superposed) or base boundary (rest)
    line: int
    start: int = 0  # motion tick in the stream, once laid out


def _limits(config: MachineConfig, axis: int) -> tuple[float, float, float]:
    """The axis's acceleration limit, the take-up's acceleration and jerk, in steps per tick² and
    tick³."""
    a = config.axes[axis]
    hz = float(config.tick_hz)
    assert a.backlash is not None
    accel = a.backlash.accel or a.max_accel
    jerk = a.backlash.jerk or accel / JERK_TIME
    return (
        a.max_accel * a.steps_per_mm / hz**2,
        accel * a.steps_per_mm / hz**2,
        jerk * a.steps_per_mm / hz**3,
    )


def _place(
    base: BaseStream,
    config: MachineConfig,
    axis: int,
    prev: int,
    new: int,
    steps: int,
    barriers: list[int],
) -> _Placed:
    """Where the take-up of `steps` goes between the axis's last motion one way (segment `prev`, −1:
    before the stream) and its first the other way (segment `new`)."""
    limit, accel, jerk = _limits(config, axis)
    ramp = design(steps, accel, jerk)
    line = _line(base, new)
    t_a = int(base.start[prev]) + int(base.step_ticks(prev, axis)[-1]) if prev >= 0 else 0
    t_b = int(base.start[new]) + int(base.step_ticks(new, axis)[0])
    lo, hi = t_a, t_b - 1  # the ramp's ticks must lie in (lo, hi]
    inside = [int(base.start[b]) for b in barriers if prev < b <= new]
    if inside:  # a pause in between: only the part after it
        lo = max(lo, inside[-1])
    room = hi - lo
    gap_ramp = ramp
    for _ in range(3):  # in the middle of the pause, with what acceleration the plan leaves there
        if room < gap_ramp.ticks:
            break
        start = lo + (room - gap_ramp.ticks) // 2
        budget = min(accel, limit - _base_accel(base, axis, start, start + gap_ramp.ticks))
        if gap_ramp.peak_accel <= budget * (1 + 1e-9):
            return _Placed(axis, gap_ramp, "gap", start, line)
        gap_ramp = design(steps, max(budget, accel * 0.01), jerk)
    if prev < 0:
        return _Placed(
            axis,
            design(steps, accel, jerk),
            "rest",
            max([0, *[b for b in barriers if b <= new]]),
            line,
        )
    rests = [b for b in range(prev + 1, new + 1) if base.rest_before[b]]
    if rests:
        middle = (t_a + t_b) / 2
        b = min(rests, key=lambda b: abs(int(base.start[b]) - middle))
        return _Placed(axis, design(steps, accel, jerk), "rest", b, line)
    backlash = config.axes[axis].backlash
    assert backlash is not None  # only an axis with backlash has take-ups
    kind = backlash.place
    section = (
        max([0, *[int(base.start[b]) for b in barriers if b <= prev]]),
        min([base.ticks, *[int(base.start[b]) for b in barriers if b > new]]),
    )
    best: tuple[int, float, int, Ramp] | None = None
    still = base.position_at(axis, t_a)  # where the axis lingers between its two motions
    full = ramp
    for start in _candidates(kind, t_a, t_b, full.ticks):
        ramp = full
        for _ in range(3):
            start = max(section[0], min(start, section[1] - ramp.ticks - 1))
            budget = min(accel, limit - _base_accel(base, axis, start, start + ramp.ticks))
            ramp = design(steps, max(budget, accel * 0.01), jerk)
        start = max(section[0], min(start, section[1] - ramp.ticks - 1))
        if (
            start < section[0]
            or limit - _base_accel(base, axis, start, start + ramp.ticks) < ramp.peak_accel
        ):
            continue
        # what the path does on this axis while the ramp runs: the carriage's error is at most that
        away = max(abs(base.position_at(axis, t) - still) for t in (start, start + ramp.ticks))
        score = (away, abs(start + ramp.ticks / 2 - (t_a + t_b) / 2), start, ramp)
        if best is None or score[:2] < best[:2]:
            best = score
    if best is None:
        raise FitError(
            f"axis {config.axes[axis].name}: no room for a take-up of {abs(steps)} steps at line "
            f"{line}"
        )
    start, ramp = best[2], best[3]
    return _Placed(axis, ramp, kind, start, line)


def _candidates(kind: str, t_a: int, t_b: int, ticks: int) -> list[int]:
    """Where a superposed ramp may begin: at the reversal (after), or anywhere it overlaps the
    axis's pause."""
    if kind == "after":
        return [t_a]
    centre = round((t_a + t_b) / 2 - ticks / 2)
    return sorted(
        {centre, t_a, t_b - ticks - 1, *range(t_a - ticks, t_b + 1, max(1, ticks // 8))},
        key=lambda s: abs(s - centre),
    )


def _base_accel(base: BaseStream, axis: int, lo: int, hi: int) -> float:
    """The largest |acceleration| of `axis` in the plan over ticks lo … hi."""
    first = int(np.searchsorted(base.start, lo, side="right")) - 1
    last = int(np.searchsorted(base.start, hi, side="left"))
    chunk = base.accel[max(first, 0) : max(last, first + 1), axis]
    return float(chunk.max()) if chunk.size else 0.0


def reversals(base: BaseStream, band: Band) -> tuple[list[tuple[int, int, int, int]], Band, Band]:
    """(axis, previous segment or −1, new segment, take-up steps) for every reversal; the band
    before (an axis not known yet adopts the side of its first motion) and after."""
    found = []
    start = band
    for axis, state in enumerate(band.axes):
        moving = np.flatnonzero(base.steps[:, axis])
        if moving.size == 0:
            continue
        direction = np.sign(base.steps[moving, axis])
        if state.size == 0:
            continue
        if state.w is None:
            state = state.adopt(int(direction[0]))
            start = start.with_axis(axis, state)
        need = state.take(int(direction[0]))
        if need:
            found.append((axis, -1, int(moving[0]), need))
        for j in np.flatnonzero(np.diff(direction)) + 1:
            found.append((axis, int(moving[j - 1]), int(moving[j]), state.size * int(direction[j])))
        state = state.monotone(int(direction[-1]) * state.size)
        band = band.with_axis(axis, state)
    found.sort(key=lambda r: (r[2], r[0]))
    return found, start, band


def compensate(
    base: BaseStream,
    config: MachineConfig,
    band: Band,
    barriers: list[int] | None = None,
    pauses: list[tuple[int, int]] | None = None,
) -> Compensated:
    """The stream with its take-ups; `barriers` (segment indices) are where it rests between
    sections."""
    barriers = sorted(set(barriers or []) | {b for b, _ in pauses or []})
    found, band_start, band_end = reversals(base, band)
    placed = [
        _place(base, config, axis, prev, new, steps, barriers) for axis, prev, new, steps in found
    ]
    return _assemble(base, config, band_start, band_end, placed, pauses or [])


def unchanged(
    segments: SegmentArrays | Stream,
    band: Band,
    pauses: Sequence[tuple[int, int]],
    entry: CubicChain | None = None,
) -> Compensated:
    """A planned stream without take-ups (none placed, or a band without backlash): its segments
    as they are."""
    out = Stream(segments)
    out.add_bases(0, len(segments))
    return Compensated(out, band, band, pauses=list(pauses), entry=entry)


def _assemble(
    base: BaseStream,
    config: MachineConfig,
    band: Band,
    band_end: Band,
    placed: list[_Placed],
    pauses: list[tuple[int, int]],
) -> Compensated:
    if not placed and isinstance(base.item, (SegmentArrays, Stream)):
        return replace(unchanged(base.item, band, pauses, base.entry), band_end=band_end)
    count = len(base)
    blocks, inserted, anchor, seg_start = _time_line(base, placed)
    units = _units(base, blocks, seg_start)
    windows = _windows(units, placed)
    # the planner's arrays (no chains) or a planned stream are the base as they are; a list of
    # items is copied
    item = base.item
    out = (
        Stream(item)
        if isinstance(item, (SegmentArrays, Stream))
        else Stream(list(item), axes=base.axis_count)
    )
    result = Compensated(
        out, band, band_end, added_ticks=int(inserted[-1]) + anchor, entry=base.entry
    )
    taken = [0] * base.axis_count  # take-up steps of the windows so far
    if anchor:
        out.add(
            Segment(
                n=1,
                axes=tuple(
                    AxisMove(axis=a, direction=1, v0=0, vn=0, r=0) for a in range(base.axis_count)
                ),
            ),
            _line(base, 0),
        )
    first_item: dict[int, int] = {}  # base boundary → index of the stream's first item there
    chain: CubicChain | None = None
    after = 0  # first base segment after the last window
    w = 0
    u = 0
    while u < len(units):
        kind, index, lo, hi = units[u]
        first_item.setdefault(index, len(out))
        if w < len(windows) and windows[w][0] == u:
            _, last, ramps = windows[w]
            chain = _chain_at(base, index, chain, after)
            spans = [span for j in range(u, last + 1) for span in _span(base, units[j], ramps)]
            begin = len(out)
            start_chain = chain.copy()
            segments, made = fit_window(chain, spans)
            _check(base, units[u : last + 1], ramps, made, config)
            for seg in segments:
                out.add(seg, _line(base, index), min(index, len(base) - 1))
            motor = tuple(int(p) + t for p, t in zip(base.position[index], taken))
            after_band = band
            for p in ramps:
                taken[p.axis] += p.ramp.steps
                after_band = after_band.with_axis(
                    p.axis, after_band.axes[p.axis].monotone(p.ramp.steps)
                )
            result.windows.append(
                Window(
                    begin,
                    len(segments),
                    lo,
                    units[last][3] - lo,
                    band,
                    after_band,
                    start_chain,
                    motor,
                )
            )
            band = after_band
            after = max(
                (units[j][1] + 1 for j in range(u, last + 1) if units[j][0] == "seg"), default=after
            )
            u = last + 1
            w += 1
            continue
        if kind == "seg":
            out.add_base(index)
        u += 1
    first_item.setdefault(count, len(out))
    hz = float(config.tick_hz)
    for p in placed:
        a = config.axes[p.axis]
        planned = int(base.start[p.at]) if p.kind == "rest" else p.at
        result.takeups.append(
            TakeUp(
                p.axis,
                p.start,
                p.ramp.ticks,
                p.ramp.steps,
                p.kind,
                p.ramp.peak_accel * hz * hz / a.steps_per_mm,
                p.line,
                planned,
            )
        )
    result.pauses = [(first_item[b], line) for b, line in pauses]
    return result


def _time_line(
    base: BaseStream, placed: list[_Placed]
) -> tuple[dict[int, int], np.ndarray, int, np.ndarray]:
    """The stream's time line: the blocks at rest (base boundary → ticks), the ticks inserted at
    boundaries ≤ b, the anchor segment's ticks, and the motion tick each base segment starts at in
    the stream; each take-up's start is set on it."""
    blocks: dict[int, int] = {}
    for p in placed:
        if p.kind == "rest":
            blocks[p.at] = max(blocks.get(p.at, 0), p.ramp.ticks + 1)
    inserted = np.zeros(len(base) + 1, dtype=np.int64)  # ticks inserted at boundaries ≤ b
    for b, length in blocks.items():
        inserted[b:] += length
    # a stream from rest begins at rest on the ideal (e = 0); one that goes on from another cannot
    anchor = 1 if placed and base.entry is None else 0
    # motion tick each base segment starts at in the stream
    seg_start = base.start + inserted + anchor
    for p in placed:
        if p.kind == "rest":
            p.start = int(seg_start[p.at]) - blocks[p.at]
        else:
            k = int(np.searchsorted(base.start, p.at, side="right")) - 1
            p.start = p.at + int(inserted[k]) + anchor
    return blocks, inserted, anchor, seg_start


Unit = tuple[str, int, int, int]  # ("seg" | "block", base index or boundary, first tick, end tick)


def _units(base: BaseStream, blocks: dict[int, int], seg_start: np.ndarray) -> list[Unit]:
    units: list[Unit] = []
    for b in range(len(base) + 1):
        if b in blocks:
            units.append(("block", b, int(seg_start[b]) - blocks[b], int(seg_start[b])))
        if b < len(base):
            units.append(("seg", b, int(seg_start[b]), int(seg_start[b]) + int(base.n[b])))
    return units


def _windows(units: list[Unit], placed: list[_Placed]) -> list[tuple[int, int, list[_Placed]]]:
    """(first unit, last unit, ramps) of each window, in order, overlapping ones merged."""
    starts = [u[2] for u in units]
    found: list[tuple[int, int, list[_Placed]]] = []
    for p in placed:
        first = int(np.searchsorted(starts, p.start, side="right")) - 1
        last = int(np.searchsorted(starts, p.start + p.ramp.ticks, side="right")) - 1
        found.append((first, last, [p]))
    found.sort(key=lambda f: f[0])
    merged: list[tuple[int, int, list[_Placed]]] = []
    for first, last, ramps in found:
        if merged and first <= merged[-1][1]:
            begin, end, together = merged[-1]
            together.extend(ramps)
            merged[-1] = (begin, max(end, last), together)
        else:
            merged.append((first, last, ramps))
    return merged


def _span(base: BaseStream, unit: Unit, ramps: list[_Placed]) -> list[Span]:
    kind, index, lo, hi = unit
    cuts = {lo, hi}
    for p in ramps:
        at = p.start
        for edge in [0, *p.ramp.boundaries()]:
            if lo < at + edge < hi:
                cuts.add(at + edge)
    edges = sorted(cuts)
    spans = []
    for a, b in zip(edges, edges[1:]):
        polys = []
        for axis in range(base.axis_count):
            poly: Poly = base.advance(index, axis, a - lo) if kind == "seg" else (Fraction(0),) * 3
            for p in ramps:
                if p.axis == axis and p.start <= a < p.start + p.ramp.ticks:
                    _, i, d, j = p.ramp.state(a - p.start)
                    poly = (poly[0] + i, poly[1] + d, poly[2] + j)
            polys.append(poly)
        spans.append(Span(b - a, tuple(polys)))
    return spans


def _line(base: BaseStream, k: int) -> int:
    lines = getattr(base.item, "line", None)
    return int(lines[min(k, len(base) - 1)]) if lines is not None and len(base) else 0


def _chain_at(base: BaseStream, k: int, previous: CubicChain | None, after: int) -> CubicChain:
    """The firmware's chain where a window begins (before base segment or boundary k): the previous
    window's end chain, moved on by the planned segments since it (quadratic ones restart the axes
    they name)."""
    if previous is not None and k == after:
        return previous
    chain = base.chain_before(k)
    if previous is not None and not base.chains:
        for axis in range(base.axis_count):
            # not named since that window: at rest, e carried
            if int(base._last_named[k - 1, axis]) < after:
                kept = previous.axes[axis]
                state = chain.axes[axis]
                state.e, state.direction, state.i, state.d = kept.e, kept.direction, 0, 0
    return chain


def _check(
    base: BaseStream,
    units: list[Unit],
    ramps: list[_Placed],
    made: list[int],
    config: MachineConfig,
) -> None:
    """The window makes exactly the planned steps plus the take-ups' (else the plan after it would
    not land)."""
    want = [0] * base.axis_count
    for kind, index, _, _ in units:
        if kind == "seg":
            for axis in range(base.axis_count):
                want[axis] += int(base.steps[index, axis])
    for p in ramps:
        want[p.axis] += p.ramp.steps
    if want != made:
        raise FitError(
            f"a take-up window makes {made} steps, not {want} (line {_line(base, units[0][1])})"
        )
