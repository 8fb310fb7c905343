"""One move's path speed over whole ticks: ramp, cruise, ramp.

The continuous time-optimal trapezoid (or triangle) is computed at the
planning acceleration; its three phases are then rounded to whole ticks and
the cruise level re-solved so the distance stays exact, within the hard
acceleration and speed limits. When no rounding can be exact (a very short
move, or a cruise-through move whose length is not a whole number of ticks
at its speed), the closest one is kept: the difference, at most about one
tick of travel, is carried into the next move by the residual chain.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

from ..kernel.fixed import N_MAX

# Phases shorter than this many ticks are worth avoiding: over a tick or two, the
# unavoidable ±1 rounding of a speed looks like a large (if harmless) acceleration.
SHORT_PHASE = 16
# A move whose top speed is within this factor of its entry or exit speed may be run as one segment
# between them, where that takes at most this factor of its time-optimal profile's time and a tick.
CRUISE_THROUGH = 1.01


@dataclass(frozen=True, slots=True)
class Profile:
    """Breakpoints of a piecewise-linear path speed: ticks[j] between speeds[j] and speeds[j+1]."""

    ticks: tuple[int, ...]
    speeds: tuple[float, ...]  # mm/tick, len(ticks) + 1
    distance_error: float  # mm the profile covers beyond the move's length (may be negative)

    @property
    def duration(self) -> int:
        return sum(self.ticks)


def _roundings(x: float) -> tuple[int, ...]:
    lo = math.floor(x)
    return (lo,) if lo == x else (lo, lo + 1)


def fit_profiles(
    length: float, u_in: float, u_out: float, u_max: float, accel: float, plan_accel: float
) -> Iterator[Profile]:
    """Whole-tick profiles from u_in to u_out over `length` mm, |accel| ≤ accel, speed ≤ u_max.

    Best first: fewest phases of only a few ticks, then exact distance (or the smallest
    error, in steps of 5% of a tick's travel), then shortest. The caller takes the first
    whose quantised form lands every axis exactly.
    """
    # entered faster than this move may go (a lowered feed override): slow down first
    slowing = u_in > u_max * (1.0 + 1e-9)
    u_max = max(u_max, u_out) if slowing else max(u_max, u_in, u_out)  # guard rounding
    peak = math.sqrt(max(0.0, (2.0 * plan_accel * length + u_in * u_in + u_out * u_out) / 2.0))
    peak = max(min(u_max, peak), u_out) if slowing else max(min(u_max, peak), u_in, u_out)
    t_a = abs(peak - u_in) / plan_accel
    t_d = (peak - u_out) / plan_accel
    exact = 1e-12 * max(length, 1e-9)
    found: list[tuple[tuple[int, int, int], tuple[int, int, int], float, float]] = []
    for n_a0 in _roundings(t_a):
        for n_d0 in _roundings(t_d):
            # whole-tick ramps cover a little more or less than the exact ones: cruise the rest
            top = max(peak, 0.0)
            rest = length - n_a0 * (u_in + top) / 2.0 - n_d0 * (top + u_out) / 2.0
            t_c = max(0.0, rest / top) if top > 0.0 else 0.0
            for n_c0 in _roundings(t_c):
                for n_a, n_c, n_d in _variants((n_a0, n_c0, n_d0)):
                    candidate = _candidate(length, u_in, u_out, u_max, accel, n_a, n_c, n_d, exact)
                    if candidate is not None:
                        found.append(candidate)
    if not slowing and all(key[0] for key, _, _, _ in found):  # each has a short phase
        found += _cruise_through(length, u_in, u_out, u_max, accel, (t_a, peak, t_d), exact)
    found.sort(key=lambda f: f[0])
    for _, phases, level, error in found:
        yield _build(u_in, u_out, phases, level, error)


def _cruise_through(
    length: float,
    u_in: float,
    u_out: float,
    u_max: float,
    accel: float,
    optimal: tuple[float, float, float],
    exact: float,
) -> list[tuple[tuple[int, int, int], tuple[int, int, int], float, float]]:
    """One phase from the entry speed to the exit, for a move cruised through a little under the
    top speed of its time-optimal profile (`optimal`: ramp ticks, top speed, ramp ticks), as a
    smooth path's short moves are, whose whole-tick profiles are a bump of short ramps; where it
    takes no more than CRUISE_THROUGH times as long as that profile, and a tick."""
    t_a, peak, t_d = optimal
    if u_in + u_out <= 0.0 or peak > CRUISE_THROUGH * max(u_in, u_out):
        return []
    cruise = max(0.0, length - t_a * (u_in + peak) / 2.0 - t_d * (peak + u_out) / 2.0) / peak
    found = []
    for n in _roundings(2.0 * length / (u_in + u_out)):
        if n <= CRUISE_THROUGH * (t_a + cruise + t_d) + 1.0:
            candidate = _candidate(length, u_in, u_out, u_max, accel, n, 0, 0, exact)
            if candidate is not None:
                found.append(candidate)
    return found


def _variants(phases: tuple[int, int, int]) -> list[tuple[int, int, int]]:
    """The phases, and, if one lasts only a few ticks, the same total split without it."""
    found = [phases]
    if not any(0 < n < SHORT_PHASE for n in phases):
        return found
    n_a, n_c, n_d = phases
    if n_c:  # a ramp takes over the cruise
        found += [(n_a + n_c, 0, n_d), (n_a, 0, n_d + n_c)]
    for short in range(3):
        for donor in range(3):
            if (
                0 < phases[short] < SHORT_PHASE
                and phases[donor] >= 2 * SHORT_PHASE
                and donor != short
            ):
                moved = list(phases)
                moved[donor] -= SHORT_PHASE - phases[short]
                moved[short] = SHORT_PHASE
                found.append((moved[0], moved[1], moved[2]))
    return found


def _candidate(
    length: float,
    u_in: float,
    u_out: float,
    u_max: float,
    accel: float,
    n_a: int,
    n_c: int,
    n_d: int,
    exact: float,
) -> tuple[tuple[int, int, int], tuple[int, int, int], float, float] | None:
    """Phases of whole ticks with the level solved for the distance; None if no level fits."""
    total = n_a + n_c + n_d
    if total == 0:
        return None
    lo = max(0.0, u_in - accel * n_a, u_out - accel * n_d)
    hi = min(u_max, u_in + accel * n_a, u_out + accel * n_d)
    if lo > hi:
        return None
    level = (2.0 * length - n_a * u_in - n_d * u_out) / (n_a + 2 * n_c + n_d)
    level = min(max(level, lo), hi)
    error = (n_a * (u_in + level) + 2 * n_c * level + n_d * (level + u_out)) / 2.0 - length
    short = sum(1 for n in (n_a, n_c, n_d) if 0 < n < SHORT_PHASE)
    # errors within 5% of a tick's travel count as equal: the residual chain carries them
    tick_travel = max(u_in, u_out, level)
    if tick_travel <= 0.0:
        return None  # standing still covers no distance
    miss = 0 if abs(error) <= exact else round(abs(error) / (0.05 * tick_travel))
    key = (short, miss, total)
    return key, (n_a, n_c, n_d), level, error


def _build(
    u_in: float, u_out: float, phases: tuple[int, int, int], level: float, error: float
) -> Profile:
    """Split the three phases into segments of at most N_MAX ticks."""
    n_a, n_c, n_d = phases
    ticks: list[int] = []
    speeds = [u_in]
    for n, a, b in ((n_a, u_in, level), (n_c, level, level), (n_d, level, u_out)):
        pieces = -(-n // N_MAX)
        for p in range(pieces):
            ticks.append(n * (p + 1) // pieces - n * p // pieces)
            speeds.append(a + (b - a) * (n * (p + 1) // pieces) / n)
    speeds[-1] = u_out
    return Profile(tuple(ticks), tuple(speeds), error)
