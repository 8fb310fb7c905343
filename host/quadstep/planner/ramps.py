"""Seed 004's acceleration-ramp move and two-step arrival, for plans of cubic segments
(docs/CUBIC.md §6).

`ramp_move` is a rest-to-rest move of one axis in whole ticks: jerk +r, 0, −r over n1, n2, n1 ticks,
then −r, 0, +r. Its second half is its first with the jerks negated, so it leaves the axis's speed
and acceleration exactly as it found them and only moves it by `ramp_distance`: it can be added to
any axis's segments (`superpose`), which is how a backlash take-up adds steps to one axis around its
reversal while the other axes' segments run on, split at the ramp's boundaries and otherwise
unchanged.

`two_step_arrival` is the seed's closed form for arriving at a position at rest in two acceleration
ramps of equal length; as checked there, it ends with an acceleration step (`a2`), zero only when
p02 = t·(3·v0 + a0·t)/3.
"""

from __future__ import annotations

from fractions import Fraction

from ..kernel.cubic_chain import AxisState, CubicChain
from ..kernel.motion import CubicAxis
from ..protocol.cubic import CubicSegment

Phase = tuple[int, int]  # (ticks, jerk in 2^-31 step per tick³)


def ramp_move(n1: int, n2: int, r: int) -> list[Phase]:
    """The seed's 7-point ramp (six intervals): +r, 0, −r, −r, 0, +r over n1, n2, n1, n1, n2, n1
    ticks."""
    if n1 < 1 or n2 < 0:
        raise ValueError(f"ramp phases need n1 ≥ 1 and n2 ≥ 0, not {n1}, {n2}")
    phases = [(n1, r), (n2, 0), (n1, -r), (n1, -r), (n2, 0), (n1, r)]
    return [p for p in phases if p[0] > 0]


def ramp_distance(phases: list[Phase]) -> int:
    """How far the ramp moves an axis from rest, in 2^-31 step (exact; it ends at rest)."""
    chain = CubicChain(1, [AxisState()])
    x = 0
    for n, r in phases:
        start = chain.axes[0]
        x += n * start.i + n * (n - 1) // 2 * start.d + n * (n - 1) * (n - 2) // 6 * r
        chain.advance(CubicSegment(n=n, axes=(CubicAxis(axis=0, jerk=r),) if r else ()))
    assert chain.axes[0].at_rest
    return x


def superpose(
    segments: list[CubicSegment], axis: int, start: int, phases: list[Phase]
) -> list[CubicSegment]:
    """`segments` with the ramp `phases` added to `axis`'s jerk from tick `start` of the run on:
    segments are split where a phase begins or ends (a piece keeps its segment's jerks; a state set
    stays on the first piece), and every other axis moves exactly as before."""
    bounds = [start]
    for n, _ in phases:
        bounds.append(bounds[-1] + n)

    def ramp_jerk(tick: int) -> int:
        return next((r for (n, r), b in zip(phases, bounds) if b <= tick < b + n), 0)

    out: list[CubicSegment] = []
    tick = 0
    for seg in segments:
        named = {m.axis: m for m in seg.axes}
        edges = sorted({tick, tick + seg.n, *(b for b in bounds if tick < b < tick + seg.n)})
        for a, b in zip(edges, edges[1:]):
            extra = ramp_jerk(a)
            axes = []
            for k in sorted(set(named) | ({axis} if extra else set())):
                m = named.get(k)
                jerk = (m.jerk or 0 if m is not None else 0) + (extra if k == axis else 0)
                if m is not None and m.speed is not None and a == tick:
                    axes.append(
                        CubicAxis(
                            axis=k,
                            speed=m.speed,
                            accel=m.accel,
                            direction=m.direction,
                            jerk=jerk if m.jerk is not None or jerk else None,
                        )
                    )
                elif jerk:
                    axes.append(CubicAxis(axis=k, jerk=jerk))
            out.append(CubicSegment(n=b - a, axes=tuple(axes)))
        tick += seg.n
    return out


def two_step_arrival(
    v0: Fraction, a0: Fraction, p02: Fraction, t: Fraction
) -> tuple[Fraction, Fraction]:
    """Accelerations a1 (at t) and a2 (at 2t) that, with the acceleration linear in between, bring
    an axis at speed v0 and acceleration a0 to rest at distance p02 after 2t (seed 004, checked)."""
    a1 = (3 * p02 - 5 * t * v0 - 2 * t * t * a0) / (2 * t * t)
    a2 = (-3 * p02 + 3 * t * v0 + t * t * a0) / (t * t)
    return a1, a2


__all__ = ["Phase", "ramp_distance", "ramp_move", "superpose", "two_step_arrival"]
