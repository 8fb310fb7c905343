"""A move's S-curve in whole ticks: the path speed v0 → vc → v1 in two jerk-limited ramps and a
cruise.

The ramps' phases are rounded up to whole ticks (never more jerk or acceleration than planned) and
the cruise speed is then solved so that the profile covers the move's length exactly
(planner/jerk.py has the closed forms). Units: mm and ticks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .jerk import ramp_distance, ramp_fits, reachable_speed, tick_ramp

# each move's profile at this share of its limits (the look-ahead plans at 0.98)
PROFILE_FRACTION = 0.995


@dataclass(frozen=True)
class Profile:
    """A move's path speeds (mm/tick) and phases in ticks: ramp (n1a, n2a, n1a), cruise nc, ramp
    (n1d, n2d, n1d)."""

    v0: float
    vc: float
    v1: float
    n1a: int
    n2a: int
    nc: int
    n1d: int
    n2d: int

    @property
    def ticks(self) -> int:
        return 2 * self.n1a + self.n2a + self.nc + 2 * self.n1d + self.n2d


def peak_speed(
    length: float, v0: float, v1: float, vmax: float, accel: float, jerk: float
) -> float:
    """The highest cruise speed ≤ vmax whose two ramps fit in `length`."""

    def distance(vc: float) -> float:
        return ramp_distance(v0, vc, accel, jerk) + ramp_distance(vc, v1, accel, jerk)

    lo, hi = max(v0, v1), max(vmax, v0, v1)
    if distance(hi) <= length:
        return hi
    # the distance grows with the peak: regula falsi (Illinois), lo always within the length,
    # until lo covers all but 1e-12 of it
    f_lo, f_hi = distance(lo) - length, distance(hi) - length
    side = 0
    for _ in range(100):
        if hi - lo <= 1e-13 * hi or f_lo >= -1e-12 * length:
            break
        mid = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        if not lo < mid < hi:
            mid = (lo + hi) / 2
        f_mid = distance(mid) - length
        if f_mid <= 0:
            lo, f_lo = mid, f_mid
            f_hi, side = (f_hi / 2 if side < 0 else f_hi), -1
        else:
            hi, f_hi = mid, f_mid
            f_lo, side = (f_lo / 2 if side > 0 else f_lo), 1
    return lo


def whole_tick_profile(
    length: float, v0: float, v1: float, vmax: float, accel: float, jerk: float
) -> Profile:
    """The S-curve in whole ticks that covers `length` exactly within the limits.

    The ramps rounded up to whole ticks for a peak speed b are long enough for any lower peak, so
    with them the cruise is the fewest whole ticks that keep the speed at most b, and the speed that
    covers `length` exactly is solved. The peak b is the time-optimal one, or lower when the
    rounding leaves no room. A cruise through (a chord of an arc at speed) keeps its speed within
    half a tick of travel; a move no ramp fits cruises a little slower than the junctions allow."""
    # after a slower exit than planned
    v1 = min(v1, reachable_speed(v0, length, accel, jerk) * (1 - 1e-9))
    best = peak_speed(length, v0, v1, vmax, accel, jerk)
    # the speed change that half a tick of travel makes over the move
    half_tick = v0 * v0 / (2 * length)
    if v0 > 0 and v1 > 0 and best - v0 <= half_tick:
        nc = max(1, round(length / v0))
        if length / nc <= min(vmax / PROFILE_FRACTION, v1 + half_tick):
            return Profile(length / nc, length / nc, length / nc, 0, 0, nc, 0, 0)
    floor = max(v0, v1)
    for k in range(12):
        b = best if k == 0 else floor + (best - floor) * 0.6**k
        profile = _solved(length, v0, v1, b, vmax, accel, jerk)
        if profile is not None:
            return profile
    slowest = min(v0, v1, vmax)
    if slowest > 0:
        nc = math.ceil(length / slowest)
        return Profile(length / nc, length / nc, length / nc, 0, 0, nc, 0, 0)
    raise ValueError("no whole-tick S-curve")


def _solved(
    length: float, v0: float, v1: float, peak: float, vmax: float, accel: float, jerk: float
) -> Profile | None:
    """The profile with the ramps rounded up for this peak speed and the cruise speed solved with
    them; a start within a tick's travel of the cruise speed takes it without a ramp (at the
    junction's speed set)."""
    one_tick = v0 * v0 / length  # the speed change that a tick of travel makes over the move
    n1a, n2a = (0, 0) if abs(peak - v0) <= one_tick else tick_ramp(peak - v0, accel, jerk)
    n1d, n2d = tick_ramp(peak - v1, accel, jerk)
    ta, td = 2 * n1a + n2a, 2 * n1d + n2d
    nc = max(0, math.ceil((length - v0 * ta / 2 - v1 * td / 2) / peak - ta / 2 - td / 2 - 1e-9))
    vc = (length - v0 * ta / 2 - v1 * td / 2) / (ta / 2 + nc + td / 2)
    exit_ = v1
    if vc < v1:  # the exit is a limit, not a must: end at the cruise speed, without a last ramp
        n1d = n2d = 0
        nc = max(0, math.ceil((length - v0 * ta / 2) / min(peak, v1) - ta / 2 - 1e-9))
        vc = exit_ = (length - v0 * ta / 2) / (ta / 2 + nc) if ta / 2 + nc else 0.0
    start = v0 if n1a else vc
    if n1a == 0 and abs(vc - v0) > one_tick:
        return None
    if (
        0 < vc <= vmax * (1 + 1e-9)
        and ramp_fits(vc - start, n1a, n2a, accel, jerk)
        and ramp_fits(vc - exit_, n1d, n2d, accel, jerk)
    ):
        return Profile(start, vc, exit_, n1a, n2a, nc, n1d, n2d)
    return None


__all__ = ["PROFILE_FRACTION", "Profile", "peak_speed", "whole_tick_profile"]
