"""Bit-exact model of the firmware's step engine (PROTOCOL.md §8).

The firmware runs the g/f loop with additions only; its result has the closed
form s(t) = floor((n·r + (vn−v0)·t² + 2·n·v0·t + n·D) / (2·n·D)), the steps
made by tick t of a segment. This module evaluates that form with exact
integers (numpy int64: every term stays below 2^35), so the host knows the
tick of every step the firmware will make, and where each axis ends.

Positions of the ideal path are tracked as integers in 1/(2D) step ("ideal2"),
so chains of segments accumulate no drift.

A HOLD decelerates from wherever the engine is; predict_hold reproduces the
firmware's state at the hold tick from the same closed form and follows the
hold's own closed form (constant change of the increment) to rest.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .cubic_chain import CubicChain
from .cubic_model import cubic_step_ticks
from .fixed import DECEL_SHIFT, MAX_AXES, N_MAX, SPEED_SHIFT, D
from .motion import AxisMove, Cubic, Quadratic


def steps_by_tick(n: int, mv: AxisMove, ticks: np.ndarray) -> np.ndarray:
    """s(t): steps made (in the direction of motion) by the end of each tick t, 0 ≤ t ≤ n."""
    t = ticks.astype(np.int64)
    s = (n * mv.r + (mv.vn - mv.v0) * t * t + 2 * n * mv.v0 * t + n * D) // (2 * n * D)
    return np.where(t == 0, 0, s)


def step_ticks(n: int, mv: AxisMove) -> np.ndarray:
    """Ticks 1..n of a segment at which this axis steps."""
    s = steps_by_tick(n, mv, np.arange(n + 1))
    return np.flatnonzero(np.diff(s)) + 1


def segment_steps(n: int, mv: AxisMove) -> int:
    """Steps this axis makes over the whole segment, in its direction of motion."""
    return int(steps_by_tick(n, mv, np.array([n]))[0])


def residual(ideal2: int, position: int, direction: int) -> int:
    """Residual r for a segment starting with the axis at `position` and the ideal at `ideal2`."""
    return direction * (ideal2 - 2 * D * position)


def advance(ideal2: int, position: int, n: int, mv: AxisMove) -> tuple[int, int]:
    """(ideal2, position) of one axis after a segment; mv.r must equal residual(ideal2, position,
    ...)."""
    return (
        ideal2 + mv.direction * n * (mv.v0 + mv.vn),
        position + mv.direction * segment_steps(n, mv),
    )


def _step_rows(ticks: np.ndarray, axis: int, direction: int) -> np.ndarray:
    """`tick, axis, direction` rows (the trace's columns) for one axis's steps at `ticks`."""
    rows = np.empty((ticks.size, 3), dtype=np.int64)
    rows[:, 0] = ticks
    rows[:, 1] = axis
    rows[:, 2] = direction
    return rows


def _stack(chunks: list[np.ndarray]) -> np.ndarray:
    return np.concatenate(chunks) if chunks else np.empty((0, 3), dtype=np.int64)


@dataclass
class Prediction:
    """Every step of a run: rows of (tick, axis, direction), in tick then axis order."""

    steps: np.ndarray
    positions: list[int]
    motion_ticks: int
    segments: int = 0
    per_axis_steps: list[int] = field(default_factory=list)


def predict(
    segments: Iterable[Quadratic | Cubic],
    positions: Sequence[int] | None = None,
    start_tick: int = 0,
    axis_count: int = MAX_AXES,
    chain: CubicChain | None = None,
) -> Prediction:
    """Predict the steps the firmware makes for `segments`, starting at motion tick `start_tick`.

    Cubic segments run on `chain`, the state the firmware's axes carry (default: a fresh firmware's,
    at rest on the ideal), which this advances; quadratic ones set it to their end state.
    """
    pos = list(positions) if positions is not None else [0] * axis_count
    counts = [0] * axis_count
    tick = start_tick
    chunks: list[np.ndarray] = []
    count = 0
    chain = chain if chain is not None else CubicChain(axis_count)
    for seg in segments:
        if isinstance(seg, Cubic):
            for step in chain.advance(seg):
                ticks = cubic_step_ticks(seg.n, step)
                if ticks.size:
                    chunks.append(_step_rows(ticks + tick, step.axis, step.start.direction))
                pos[step.axis] += step.start.direction * int(ticks.size)
                counts[step.axis] += int(ticks.size)
            tick += seg.n
            count += 1
            continue
        totals = {}
        for mv in seg.axes:
            ticks = step_ticks(seg.n, mv)
            if ticks.size:
                chunks.append(_step_rows(ticks + tick, mv.axis, mv.direction))
            pos[mv.axis] += mv.direction * int(ticks.size)
            counts[mv.axis] += int(ticks.size)
            totals[mv.axis] = int(ticks.size)
        chain.follow_quadratic(seg, totals)
        tick += seg.n
        count += 1
    steps = _stack(chunks)
    steps = steps[np.lexsort((steps[:, 1], steps[:, 0]))]
    return Prediction(
        steps=steps,
        positions=pos,
        motion_ticks=tick - start_tick,
        segments=count,
        per_axis_steps=counts,
    )


# --- HOLD: deceleration to rest from any tick (docs/FIXED_POINT.md §8) ----------------------------

HOLD_CHUNK = 1 << 20  # ticks evaluated at once, so that long holds stay small in memory


def hold_shift(n: int) -> int:
    """log2 k: the largest power of two with k·n ≤ N_MAX, by which the firmware rescales the held
    segment."""
    shift = 0
    while n << (shift + 1) <= N_MAX:
        shift += 1
    return shift


def hold_step_change(kn: int, decel: int) -> int:
    """The per-tick change of the increment, in the scale 2·kn·D, for decel/2^24 step per tick²:
    −max(1, ⌊kn·decel/2^11⌋)."""
    return -max(1, (kn * decel) >> (DECEL_SHIFT - SPEED_SHIFT - 1))


@dataclass(frozen=True)
class AxisHold:
    """One axis of a hold, exactly as the firmware runs it, in the rescaled segment's scale w =
    2·kn·D.

    The ideal position relative to the stepper at the hold tick is (e0 + j·i1 + d·j(j−1)/2)/w after
    j ≤ stop hold ticks; the stepper has made ⌊(that·w + kn·D)/w⌋ steps (0 at j = 0).
    """

    kn: int
    e0: int  # k·(2nD·x(t0) − 2nD·s(t0)): the scaled distance of the ideal ahead of the stepper
    i1: int  # k·(X(t0+1) − X(t0)): the scaled increment over the first hold tick
    d: int  # the increment's change per tick (< 0)
    before: int  # steps the segment made before the hold, s(t0)

    @property
    def w(self) -> int:
        return 2 * self.kn * D

    @property
    def stop(self) -> int:
        """Hold ticks that make a decision: until the increment after one would be ≤ 0."""
        return -(-self.i1 // -self.d) if self.i1 > 0 else 0

    def steps(self, j: np.ndarray) -> np.ndarray:
        """Steps made after j hold ticks (j ≤ stop), in the direction of motion."""
        j = j.astype(np.int64)
        ideal = self.e0 + j * self.i1 + self.d * (j * (j - 1) // 2)
        return np.where(j == 0, 0, (ideal + self.kn * D) // self.w)


def axis_hold(n: int, mv: AxisMove, t0: int, decel: int) -> AxisHold:
    """The state a hold takes over after t0 ≤ n ticks of a segment, from the closed form, rescaled.

    At t0 = n (a hold at the segment's end: an underrun, or a HOLD with nothing queued behind it)
    the first hold tick runs at the end speed, i1 = k·2n·vn, not the quadratic's continuation."""
    if not 0 <= t0 <= n:
        raise ValueError(f"t0 = {t0} outside the segment's ticks 0..{n}")
    k = 1 << hold_shift(n)
    c1 = mv.vn - mv.v0
    x = n * mv.r + c1 * t0 * t0 + 2 * n * mv.v0 * t0  # 2nD·x(t0)
    before = int(steps_by_tick(n, mv, np.array([t0]))[0])
    i1 = 2 * n * mv.vn if t0 == n else 2 * n * mv.v0 + c1 * (2 * t0 + 1)
    return AxisHold(
        kn=k * n,
        e0=k * (x - 2 * n * D * before),
        i1=k * i1,
        d=hold_step_change(k * n, decel),
        before=before,
    )


@dataclass
class HoldPrediction:
    """What a hold does: every step after hold_tick, where each axis rests and when the last
    stops."""

    hold_tick: int
    motion_ticks: int
    positions: list[int]
    steps: np.ndarray  # rows (tick, axis, direction) after hold_tick, in tick then axis order
    held: int | None  # index of the segment the hold began in (None: nothing was running)


def predict_hold(
    segments: Sequence[Quadratic],
    hold_tick: int,
    decels: Sequence[int],
    positions: Sequence[int] | None = None,
    start_tick: int = 0,
    axis_count: int = MAX_AXES,
) -> HoldPrediction:
    """Predict a HOLD (decels[axis] in 1/2^24 step per tick²) that began at motion tick `hold_tick`.

    `segments` are those sent since motion tick `start_tick`; the hold discards every one after the
    segment running at hold_tick (at a boundary: the one starting there). At the end of the last
    segment, if it ends moving, the hold begins from its end (an underrun's hold:
    `predict_underrun`). The firmware reports hold_tick in HOLD_DONE, so a host predicts every step
    of the hold exactly.
    """
    pos = list(positions) if positions is not None else [0] * axis_count
    tick = start_tick
    if hold_tick < start_tick:
        raise ValueError(f"hold tick {hold_tick} is before the first segment's start {start_tick}")
    for index, seg in enumerate(segments):
        if hold_tick < tick + seg.n:
            return _hold_segment(seg, index, hold_tick - tick, hold_tick, decels, pos)
        if (
            hold_tick == tick + seg.n
            and index == len(segments) - 1
            and any(mv.vn for mv in seg.axes)
        ):
            return _hold_segment(seg, index, seg.n, hold_tick, decels, pos)
        for mv in seg.axes:
            pos[mv.axis] += mv.direction * segment_steps(seg.n, mv)
        tick += seg.n
    if hold_tick != tick:
        raise ValueError(f"hold tick {hold_tick} is after the end of the segments ({tick})")
    return HoldPrediction(hold_tick, hold_tick, pos, _stack([]), None)


def predict_underrun(
    segments: Sequence[Quadratic],
    decels: Sequence[int],
    positions: Sequence[int] | None = None,
    start_tick: int = 0,
    axis_count: int = MAX_AXES,
) -> HoldPrediction:
    """The controlled stop after the last of `segments` when nothing follows it (PROTOCOL.md §8.1):
    a hold at the firmware's stop decelerations (CONFIG's hold_decel) from where that segment
    ended."""
    end = start_tick + sum(seg.n for seg in segments)
    return predict_hold(segments, end, decels, positions, start_tick, axis_count)


def _hold_segment(
    seg: Quadratic, index: int, t0: int, hold_tick: int, decels: Sequence[int], pos: list[int]
) -> HoldPrediction:
    chunks: list[np.ndarray] = []
    last = 0
    for mv in seg.axes:
        hold = axis_hold(seg.n, mv, t0, decels[mv.axis])
        made = hold.before
        for first in range(1, hold.stop + 1, HOLD_CHUNK):
            j = np.arange(first - 1, min(first + HOLD_CHUNK, hold.stop + 1))
            s = hold.steps(j)
            ticks = j[1:][np.diff(s) > 0]
            if ticks.size:
                chunks.append(_step_rows(ticks + hold_tick, mv.axis, mv.direction))
            made = hold.before + int(s[-1])
        pos[mv.axis] += mv.direction * made
        last = max(last, hold.stop)
    steps = _stack(chunks)
    steps = steps[np.lexsort((steps[:, 1], steps[:, 0]))]
    return HoldPrediction(hold_tick, hold_tick + last, pos, steps, index)
