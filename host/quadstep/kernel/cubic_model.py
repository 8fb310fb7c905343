"""Bit-exact model of the firmware's cubic segments (docs/CUBIC.md, firmware/core/qs_cubic.c).

Per axis, in its direction of motion and in 2^-31 step, the ideal advances I(k) over tick k of a
segment, I(k) = i + (k−1)·d + C(k−1, 2)·r, starting from the state (e, i, d) the axis carries: e the
ideal ahead of the stepper, i the next advance, d its change per tick. The stepper has made
floor((e + X(t) + Σ/2)/Σ) steps by tick t ≥ 1 of the segment, X(t) = t·i + C(t,2)·d + C(t,3)·r, and
the state after it is exact, so a chain of any length predicts every step.

The chain of state itself, checked and advanced as the firmware does, is cubic_chain.py.
"""

from __future__ import annotations

import numpy as np

from .cubic_chain import CubicStep
from .fixed import CUBIC_SHIFT, HALF


def cubic_steps_by_tick(step: CubicStep, ticks: np.ndarray) -> np.ndarray:
    """Steps made by the end of each tick t (0 ≤ t ≤ n), in the direction of motion."""
    t = ticks.astype(np.int64)
    s = step.start
    x = t * s.i + (t * (t - 1) // 2) * s.d + (t * (t - 1) * (t - 2) // 6) * step.r
    made = (s.e + x + HALF) >> CUBIC_SHIFT
    return np.where(t == 0, 0, made)


def cubic_step_ticks(n: int, step: CubicStep) -> np.ndarray:
    """Ticks 1..n of a segment at which this axis steps."""
    made = cubic_steps_by_tick(step, np.arange(n + 1))
    return np.flatnonzero(np.diff(made)) + 1


__all__ = ["cubic_step_ticks", "cubic_steps_by_tick"]
