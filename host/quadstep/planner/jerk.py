"""Jerk-limited speed changes along a path: the closed forms the S-curve planner and its look-ahead
use.

A *ramp* changes the path speed from va to vb with the acceleration 0 at both ends: jerk ±J for T1,
constant acceleration for T2, jerk ∓J for T1. The speed change is J·T1·(T1 + T2); when it is at most
A²/J the acceleration never reaches A (T2 = 0, T1 = √(Δv/J)), otherwise T1 = A/J and T2 = Δv/A −
A/J. The speed is point-symmetric about the ramp's middle, so the ramp covers (va + vb)/2 · (2·T1 +
T2). Over a distance L, the speed reachable from v is therefore not √(v² + 2AL) but the root of that
distance equal to L (`reachable_speed`). Units: mm and ticks.
"""

from __future__ import annotations

import math


def ramp_times(dv: float, accel: float, jerk: float) -> tuple[float, float]:
    """(T1, T2) of the ramp that changes the speed by |dv| at these limits."""
    dv = abs(dv)
    if dv * jerk <= accel * accel:
        return math.sqrt(dv / jerk), 0.0
    return accel / jerk, dv / accel - accel / jerk


def ramp_distance(va: float, vb: float, accel: float, jerk: float) -> float:
    t1, t2 = ramp_times(vb - va, accel, jerk)
    return (va + vb) / 2 * (2 * t1 + t2)


def reachable_speed(v: float, length: float, accel: float, jerk: float) -> float:
    """The highest speed a ramp from speed v reaches within `length` (and, the ramp being
    reversible, the highest speed from which v is reachable)."""
    if math.isinf(jerk):
        return math.sqrt(v * v + 2.0 * accel * length)
    # acceleration below its limit: (2v + Δv)·√(Δv/J) = L, i.e. s³ + 2v·s = L·√J with s = √Δv
    p, q = 2.0 * v, length * math.sqrt(jerk)
    if p**3 < 1e-24 * q * q:  # the speed is negligible beside the change: s³ = q
        s = q ** (1.0 / 3.0)
    else:
        s = 2.0 * math.sqrt(p / 3.0) * math.sinh(math.asinh(1.5 * q / p * math.sqrt(3.0 / p)) / 3.0)
    dv = s * s
    if dv * jerk > accel * accel:
        # with a constant-acceleration phase: Δv² + (2v + A²/J)·Δv + 2v·A²/J − 2AL = 0
        b = 2.0 * v + accel * accel / jerk
        c = 2.0 * v * accel * accel / jerk - 2.0 * accel * length
        dv = -2.0 * c / (b + math.sqrt(b * b - 4.0 * c))
    return v + dv


def tick_ramp(dv: float, accel: float, jerk: float) -> tuple[int, int]:
    """(n1, n2): the ramp's phases in whole ticks, each rounded up, so that the jerk and
    acceleration it needs for |dv| stay within the limits (none for no change)."""
    if dv == 0.0:
        return 0, 0
    t1, t2 = ramp_times(dv, accel, jerk)
    n1 = max(1, math.ceil(t1 - 1e-9))
    n2 = max(0, math.ceil(t2 - 1e-9))
    return n1, n2


def ramp_fits(dv: float, n1: int, n2: int, accel: float, jerk: float) -> bool:
    """Whether |dv| over phases (n1, n2, n1) needs no more than these limits."""
    dv = abs(dv)
    if dv == 0.0:
        return True
    if n1 == 0:
        return False
    return dv <= jerk * n1 * (n1 + n2) * (1 + 1e-12) and dv <= accel * (n1 + n2) * (1 + 1e-12)


__all__ = ["ramp_distance", "ramp_fits", "ramp_times", "reachable_speed", "tick_ramp"]
