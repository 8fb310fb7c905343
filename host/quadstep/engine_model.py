"""Bit-exact model of the firmware's step engine (PROTOCOL.md §8).

The firmware runs the g/f loop with additions only; its result has the closed
form s(t) = floor((n·r + (vn−v0)·t² + 2·n·v0·t + n·D) / (2·n·D)), the steps
made by tick t of a segment. This module evaluates that form with exact
integers (numpy int64: every term stays below 2^35), so the host knows the
tick of every step the firmware will make, and where each axis ends.

Positions of the ideal path are tracked as integers in 1/(2D) step ("ideal2"),
so chains of segments accumulate no drift.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .protocol.segment import D, MAX_AXES, AxisMove, Segment


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
    """(ideal2, position) of one axis after a segment; mv.r must equal residual(ideal2, position, ...)."""
    return (
        ideal2 + mv.direction * n * (mv.v0 + mv.vn),
        position + mv.direction * segment_steps(n, mv),
    )


@dataclass
class Prediction:
    """Every step of a run: rows of (tick, axis, direction), in tick then axis order."""

    steps: np.ndarray
    positions: list[int]
    motion_ticks: int
    segments: int = 0
    per_axis_steps: list[int] = field(default_factory=list)


def predict(
    segments: Iterable[Segment],
    positions: Sequence[int] | None = None,
    start_tick: int = 0,
    axis_count: int = MAX_AXES,
) -> Prediction:
    """Predict the steps the firmware makes for `segments`, starting at motion tick `start_tick`."""
    pos = list(positions) if positions is not None else [0] * axis_count
    counts = [0] * axis_count
    tick = start_tick
    chunks: list[np.ndarray] = []
    count = 0
    for seg in segments:
        for mv in seg.axes:
            ticks = step_ticks(seg.n, mv)
            if ticks.size:
                rows = np.empty((ticks.size, 3), dtype=np.int64)
                rows[:, 0] = ticks + tick
                rows[:, 1] = mv.axis
                rows[:, 2] = mv.direction
                chunks.append(rows)
            pos[mv.axis] += mv.direction * int(ticks.size)
            counts[mv.axis] += int(ticks.size)
        tick += seg.n
        count += 1
    steps = np.concatenate(chunks) if chunks else np.empty((0, 3), dtype=np.int64)
    steps = steps[np.lexsort((steps[:, 1], steps[:, 0]))]
    return Prediction(steps=steps, positions=pos, motion_ticks=tick - start_tick, segments=count, per_axis_steps=counts)
