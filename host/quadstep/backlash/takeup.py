"""The take-up: seed 004's 7-point acceleration ramp, sized for a distance within an acceleration
and a jerk.

Jerk +r, 0, −r over n1, n2, n1 ticks, then −r, 0, +r (planner/ramps.py): the axis gains exactly the
speed and acceleration back that it had, so the ramp can be added to any motion. Its distance with r
= 1 is K(n1, n2) in 2^-31 step; the ramp is scaled by distance/(r·K) to be exactly `steps` long (the
scale differs from 1 by less than 1/(2r): the integer jerks of the cubic segments follow it and the
fitter absorbs the rest). Units: steps and ticks; accelerations in steps per tick², jerks in steps
per tick³.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from ..kernel.cubic_chain import choose2, choose3
from ..kernel.fixed import SIGMA
from ..planner.ramps import Phase, ramp_distance, ramp_move

# the jerk in 2^-31 step per tick³ is kept at least this large: its rounding stays tiny
MIN_JERK_UNITS = 1024
MAX_JERK_UNITS = (1 << 15) - 1  # the wire's i16


class TakeUpError(ValueError):
    """A take-up that cannot be made within the limits given."""


@dataclass(frozen=True)
class Ramp:
    """A take-up of `steps` (signed) over 4·n1 + 2·n2 ticks, jerk ±r (2^-31 step per tick³) scaled
    by `scale`."""

    steps: int
    n1: int
    n2: int
    r: int  # ≥ 1, the magnitude; the sign of `steps` gives the direction
    scale: Fraction

    @property
    def ticks(self) -> int:
        return 4 * self.n1 + 2 * self.n2

    @property
    def direction(self) -> int:
        return 1 if self.steps > 0 else -1

    def phases(self) -> list[Phase]:
        """(ticks, jerk) of the unscaled ramp, signed in its direction."""
        return ramp_move(self.n1, self.n2, self.direction * self.r)

    @property
    def peak_accel(self) -> float:
        """Largest acceleration, steps per tick²."""
        return float(self.n1 * self.r * self.scale) / SIGMA

    @property
    def peak_jerk(self) -> float:
        return float(self.r * self.scale) / SIGMA

    def state(self, t: int) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """(x, i, d, jerk) after t ticks, signed, scaled, in 2^-31 step: the distance made, the
        advance over the next tick, its change per tick, and the jerk of the next tick."""
        x = i = d = jerk = 0
        at = 0
        for n, r in self.phases():
            run = min(max(t - at, 0), n)
            x += run * i + choose2(run) * d + choose3(run) * r
            i += run * d + choose2(run) * r
            d += run * r
            if at <= t < at + n:
                jerk = r
            at += n
        return self.scale * x, self.scale * i, self.scale * d, self.scale * jerk

    def boundaries(self) -> list[int]:
        """Ticks (from the ramp's start) where its jerk changes, the end included."""
        out, at = [], 0
        for n, _ in self.phases():
            at += n
            out.append(at)
        return out


def design(steps: int, accel: float, jerk: float) -> Ramp:
    """The shortest ramp of `steps` (≠ 0) whose acceleration stays within `accel` and jerk within
    `jerk`."""
    if steps == 0:
        raise TakeUpError("a take-up of 0 steps")
    if accel <= 0 or jerk <= 0:
        raise TakeUpError(f"take-up acceleration {accel} and jerk {jerk} must be positive")
    distance = abs(steps)
    jerk = min(jerk, MAX_JERK_UNITS / SIGMA)
    n1 = max(1, math.ceil(accel / jerk))  # ticks to reach the acceleration at this jerk
    # short: jerk-limited, no n2
    n1 = max(1, min(n1, math.ceil((distance / (2.0 * jerk)) ** (1.0 / 3.0))))
    n2 = 0
    if 2.0 * n1 * n1 * n1 * jerk < distance:
        a = min(accel, n1 * jerk)
        n2 = max(0, math.ceil((-3.0 * n1 + math.sqrt(n1 * n1 + 4.0 * distance / a)) / 2.0))

    def fits(n1: int, n2: int) -> Fraction | None:
        """The ramp's exact jerk (2^-31 step per tick³) if (n1, n2) stays within the limits."""
        exact = Fraction(distance * SIGMA, ramp_distance(ramp_move(n1, n2, 1)))
        ok = (
            exact <= jerk * SIGMA and n1 * exact <= accel * SIGMA and round(exact) <= MAX_JERK_UNITS
        )
        return exact if ok else None

    while (exact := fits(n1, n2)) is None:
        n2 += max(1, n2 // 16)
    # a gentle ramp: shorter jerk phases, longer constant ones, same time
    while exact < MIN_JERK_UNITS and n1 > 1:
        shorter = fits(n1 - 1, n2 + 2)
        if shorter is None:
            break
        n1, n2, exact = n1 - 1, n2 + 2, shorter
    r = max(1, round(exact))
    unit = ramp_distance(ramp_move(n1, n2, 1))
    return Ramp(steps=steps, n1=n1, n2=n2, r=r, scale=Fraction(distance * SIGMA, r * unit))


__all__ = ["Ramp", "TakeUpError", "design"]
