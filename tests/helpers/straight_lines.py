"""Straight lines planned as S-curves, and how far their stepped path strays from the line: shared by
tests/planner/test_scurve_straight.py and tests/bench/bench_scurve.py."""

from __future__ import annotations

import random
import tempfile
from pathlib import Path

import numpy as np

from quadstep.config import MachineConfig
from quadstep.job import load_job
from quadstep.kernel.engine_model import predict


def steps_off_the_line(gcode: str, config: MachineConfig) -> float:
    """How far, in steps, the stepped path of a job from the origin strays from the line to where it
    ends."""
    with tempfile.TemporaryDirectory() as work:
        path = Path(work) / "line.gcode"
        path.write_text(gcode)
        job = load_job(path, config, (0,) * len(config.axes))
    steps = predict(job.plan.segments.segments(), axis_count=len(config.axes)).steps
    moves = np.zeros((len(steps), len(config.axes)))
    moves[np.arange(len(steps)), steps[:, 1]] = steps[:, 2]
    positions = np.cumsum(moves, axis=0)
    end = np.array(job.plan.end, dtype=float)
    assert tuple(positions[-1]) == tuple(end)
    along = positions @ end / (end @ end)
    return float(np.max(np.linalg.norm(positions - along[:, None] * end, axis=1)))


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
