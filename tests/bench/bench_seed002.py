#!/usr/bin/env python3
"""Seed 002's integer spline stepping against quadstep's cubic segments: the drift from the exact
cubic as a function of the segment length n.

Seed 002 steps x(t+1) = x(t) + p, p += q, q += r in 16.16 fixed point, with p(0) = a + b + c,
q(0) = 6a + 2b, r = 6a rounded to the nearest 1/65536 ("accurate for about 64 steps"). Over random
cubics whose speed stays within 0..1 step per tick, this prints, for each n, the worst and median
distance (in steps) between the position it steps to (x rounded to a step) and the exact cubic,
beside the same for quadstep's cubic segment (docs/CUBIC.md), whose step position is exact by
construction (within half a step at every tick, exactly, checked here tick by tick).

    python3 tests/bench/bench_seed002.py [--segments N]
"""

from __future__ import annotations

import argparse
import random
import statistics
from fractions import Fraction

import numpy as np

from quadstep.kernel.fixed import SIGMA
from quadstep.kernel.cubic_chain import AxisState, CubicStep
from quadstep.kernel.cubic_model import cubic_steps_by_tick

LENGTHS = (16, 32, 44, 64, 75, 128, 256, 512, 1022)


def random_cubic(rng: random.Random, n: int) -> tuple[Fraction, Fraction, Fraction]:
    """(v0, a0, j) per tick whose speed v0 + a0 t + j t²/2 stays within 0..1 over 0..n."""
    while True:
        v0 = Fraction(rng.randint(0, 1 << 20), 1 << 20)
        a0 = Fraction(rng.randint(-(1 << 20), 1 << 20), (1 << 20) * n)
        j = Fraction(rng.randint(-(1 << 20), 1 << 20), (1 << 20) * n * n)
        speeds = [v0 + a0 * t + j * t * t / 2 for t in (0, n)]
        if j and 0 < -a0 / j < n:
            tv = -a0 / j
            speeds.append(v0 + a0 * tv + j * tv * tv / 2)
        if all(0 <= s <= 1 for s in speeds):
            return v0, a0, j


def seed002_worst(v0: Fraction, a0: Fraction, j: Fraction, n: int) -> float:
    """Worst |stepped position − exact| over the segment, seed 002's 16.16 differencing."""
    one = 1 << 16
    # x(t) = a t³ + b t² + c t: a = j/6, b = a0/2, c = v0
    a, b, c = j / 6, a0 / 2, v0
    p = round((a + b + c) * one)
    q = round((6 * a + 2 * b) * one)
    r = round(6 * a * one)
    x = 0
    worst = 0.0
    for t in range(1, n + 1):
        x += p
        p += q
        q += r
        exact = a * t**3 + b * t**2 + c * t
        stepped = (x + one // 2) // one  # the stepper on the nearest step of its x
        worst = max(worst, abs(float(stepped - exact)))
    return worst


def ours_worst(v0: Fraction, a0: Fraction, j: Fraction, n: int) -> float:
    """The same for a cubic segment: the state the host sends, rounded once, stepped exactly."""
    i = round((v0 + a0 / 2 + j / 6) * SIGMA)
    d = round((a0 + j) * SIGMA)
    r = round(j * SIGMA)
    step = CubicStep(0, AxisState(0, i, d), r, 0)
    made = cubic_steps_by_tick(step, np.arange(n + 1))
    worst = 0.0
    for t in range(1, n + 1):
        exact = v0 * t + a0 * t * t / 2 + j * t**3 / 6
        worst = max(worst, abs(float(int(made[t]) - exact)))
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=60, help="random cubics per length")
    args = parser.parse_args()
    rng = random.Random(2)
    print("distance from the ideal cubic, steps (worst over each segment; median and worst over "
          f"{args.segments} random segments with speeds in 0..1 step per tick)")
    print(f"{'n':>6} {'seed 002 median':>16} {'seed 002 worst':>15} {'quadstep worst':>15}")
    for n in LENGTHS:
        theirs, ours = [], []
        for _ in range(args.segments):
            v0, a0, j = random_cubic(rng, n)
            theirs.append(seed002_worst(v0, a0, j, n))
            ours.append(ours_worst(v0, a0, j, n))
        print(f"{n:>6} {statistics.median(theirs):>16.3f} {max(theirs):>15.3f} {max(ours):>15.3f}")


if __name__ == "__main__":
    main()
