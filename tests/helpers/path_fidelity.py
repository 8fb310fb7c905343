"""How far a plan's stepped path strays from the G-code's polyline (each move's straight line from
where the one before ended), and straight lines to measure it on: shared by
tests/planner/test_scurve_path.py and tests/bench/bench_scurve.py."""

from __future__ import annotations

import random

import numpy as np

from quadstep.planner.plan import Plan
from quadstep.kernel.engine_model import predict


def steps_off_the_path(plan: Plan) -> float:
    """The largest distance, in steps, from any position the steppers pass through during a move to
    that move's line (from where the steppers stood as the move before ended to where they stand as
    it ends)."""
    axes = plan.segments.axis_count
    steps = predict(plan.segments.segments(), axis_count=axes).steps
    moved = np.zeros((len(steps), axes))
    moved[np.arange(len(steps)), steps[:, 1]] = steps[:, 2]
    positions = np.cumsum(moved, axis=0) + np.array(plan.start, dtype=float)
    assert tuple(positions[-1]) == tuple(plan.end)
    ends = np.concatenate([[0], np.cumsum(np.asarray(plan.segments.n, dtype=np.int64))])
    move_ends = ends[np.asarray(plan.move_ends, dtype=np.int64)]
    # step rows up to each move's end; the positions there
    upto = np.searchsorted(steps[:, 0], move_ends, side="right")
    start = np.array(plan.start, dtype=float)
    corners = np.vstack([start, *[positions[i - 1] if i else start for i in upto]])
    worst, first = 0.0, 0
    for k, last in enumerate(upto):
        if last > first:
            a, b = corners[k], corners[k + 1]
            line = b - a
            length2 = line @ line
            p = positions[first:last]
            t = np.clip((p - a) @ line / length2, 0, 1) if length2 else np.zeros(len(p))
            worst = max(worst, float(np.max(np.linalg.norm(p - (a + t[:, None] * line), axis=1))))
        first = last
    return worst


def lines(seed: int, count: int) -> list[str]:
    """Straight lines from the origin in any direction within a router's travel (X, Y 0 … 150 mm, Z
    −5 … 0), at several feeds, some cut into collinear pieces."""
    rng = random.Random(seed)
    out = []
    for _ in range(count):
        x, y, z = rng.uniform(0, 150), rng.uniform(0, 150), rng.uniform(-5, 0)
        pieces = rng.choice([1, 1, 3, 10])
        body = "".join(
            f"G1 X{x * k / pieces:.4f} Y{y * k / pieces:.4f} Z{z * k / pieces:.4f}\n"
            for k in range(1, pieces + 1)
        )
        out.append(f"G21 G90 F{rng.choice([300, 600, 1200, 2400])}\n{body}")
    return out
