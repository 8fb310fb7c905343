"""A plan read back as physical quantities over time, for plots and summaries."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..protocol.segment import D
from .plan import Plan


@dataclass(frozen=True)
class Timeline:
    """Per segment s and axis i, in seconds, mm/s, mm/s² and mm (ideal positions)."""

    start: np.ndarray  # (S,) time each segment starts
    end: np.ndarray  # (S,) time it ends
    speed0: np.ndarray  # (S, axes) signed speed at the start
    speed1: np.ndarray  # (S, axes) signed speed at the end
    accel: np.ndarray  # (S, axes) constant within the segment
    position: np.ndarray  # (S + 1, axes) ideal position at every boundary


def timeline(plan: Plan) -> Timeline:
    config = plan.config
    a = plan.segments.numpy()
    hz = float(config.tick_hz)
    count = plan.segments.axis_count
    n = a["n"].astype(np.int64)
    ends = np.cumsum(n)
    bits = a["axes"].astype(np.int64)
    active = np.stack([(bits >> i) & 1 for i in range(count)], axis=1)
    sign = np.where(np.stack([(bits >> (4 + i)) & 1 for i in range(count)], axis=1) == 1, -1, 1) * active
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
