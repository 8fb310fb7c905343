"""A plan read back as physical quantities over time, for plots and summaries."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernel.cubic_chain import CubicChain
from ..kernel.fixed import SIGMA, D
from ..protocol.cubic import CubicSegment
from .plan import Plan
from .stream import Stream


@dataclass(frozen=True)
class Timeline:
    """Per segment s and axis i, in seconds, mm/s, mm/s² and mm (ideal positions)."""

    start: np.ndarray  # (S,) time each segment starts
    end: np.ndarray  # (S,) time it ends
    speed0: np.ndarray  # (S, axes) signed speed at the start
    speed1: np.ndarray  # (S, axes) signed speed at the end
    accel: np.ndarray  # (S, axes) at the start of each segment
    position: np.ndarray  # (S + 1, axes) ideal position at every boundary
    # (S, axes) at the end, where it changes within segments (cubic)
    accel1: np.ndarray | None = None


def timeline(plan: Plan) -> Timeline:
    if isinstance(plan.segments, Stream):
        return _cubic_timeline(plan)
    config = plan.config
    a = plan.segments.numpy()
    hz = float(config.tick_hz)
    count = plan.segments.axis_count
    n = a["n"].astype(np.int64)
    ends = np.cumsum(n)
    bits = a["axes"].astype(np.int64)
    active = np.stack([(bits >> i) & 1 for i in range(count)], axis=1)
    sign = (
        np.where(np.stack([(bits >> (4 + i)) & 1 for i in range(count)], axis=1) == 1, -1, 1)
        * active
    )
    steps_per_mm = np.array([axis.steps_per_mm for axis in config.axes])
    flip = np.array([-1.0 if axis.invert else 1.0 for axis in config.axes])
    per_quantum = hz / D / steps_per_mm * flip  # mm/s per unit of v
    v0 = sign * a["v0"].astype(np.int64)
    vn = sign * a["vn"].astype(np.int64)
    travel2 = n[:, None] * (v0 + vn)  # 1/8192 step
    start2 = 2 * D * np.array(plan.start, dtype=np.int64)
    ideal2 = np.vstack([start2, start2 + np.cumsum(travel2, axis=0)])
    return Timeline(
        start=(ends - n) / hz,
        end=ends / hz,
        speed0=v0 * per_quantum,
        speed1=vn * per_quantum,
        accel=(vn - v0) * per_quantum / np.maximum(n, 1)[:, None] * hz,
        position=ideal2 / (2 * D) / steps_per_mm * flip,
    )


def _cubic_timeline(plan: Plan) -> Timeline:
    """A jerk-limited plan: the firmware's chain walked segment by segment (the anchor tick at
    rest)."""
    config = plan.config
    hz = float(config.tick_hz)
    count = len(config.axes)
    scale = np.array([(-1.0 if a.invert else 1.0) / a.steps_per_mm for a in config.axes])
    chain = CubicChain(count)
    rows: list[tuple[np.ndarray, ...]] = []
    position = np.array(plan.start, dtype=np.float64)
    positions = [position.copy()]
    for seg in plan.segments.segments():
        starts = (
            chain.starts(seg) if isinstance(seg, CubicSegment) else [(a, 0) for a in chain.axes]
        )
        v0 = np.array([s.direction * s.i for s, _ in starts], dtype=np.float64)
        a0 = np.array([s.direction * s.d for s, _ in starts], dtype=np.float64)
        if isinstance(seg, CubicSegment):
            for step in chain.advance(seg):
                position[step.axis] += step.start.direction * step.steps
        else:
            chain.follow_quadratic(seg, {m.axis: 0 for m in seg.axes})
        v1 = np.array([a.direction * a.i for a in chain.axes], dtype=np.float64)
        a1 = np.array([a.direction * a.d for a in chain.axes], dtype=np.float64)
        rows.append((v0, v1, a0, a1))
        positions.append(position + np.array([a.direction * a.e for a in chain.axes]) / SIGMA)
    n = np.array(plan.segments.n, dtype=np.int64)
    ends = np.cumsum(n)
    v0, v1, a0, a1 = (np.array([r[j] for r in rows]).reshape(-1, count) for j in range(4))
    return Timeline(
        start=(ends - n) / hz,
        end=ends / hz,
        speed0=v0 / SIGMA * hz * scale,
        speed1=v1 / SIGMA * hz * scale,
        accel=a0 / SIGMA * hz * hz * scale,
        position=np.array(positions) * scale,
        accel1=a1 / SIGMA * hz * hz * scale,
    )
