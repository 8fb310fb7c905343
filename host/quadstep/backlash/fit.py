"""Exact motion → CUBIC_SEGMENTs: the firmware's integer chain made to follow a wanted ideal, to the
quantum.

The wanted ideal of each axis is given span by span as its advance per tick, a polynomial with exact
rational coefficients (a planned segment plus a take-up ramp). Each cubic segment the fitter makes
is a piece over which every axis keeps one direction; per axis it carries the chain's state where
that is exactly the wanted one, and otherwise sets a speed and an acceleration, rounded so that the
chain's ideal ends the piece at most one quantum per tick ahead of the wanted one (2^-31 step per
tick: nothing a stepper can show). The last tick of a window lands the chain's ideal exactly on the
wanted one, so the planned segments after the window run as planned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

from ..kernel.cubic_chain import AxisState, CubicChain, advances_in_range, choose2, choose3
from ..kernel.fixed import CUBIC_ACCEL_LIMIT, SIGMA
from ..kernel.motion import CubicAxis, Direction
from ..protocol.cubic import CubicSegment
from .base import Poly

MAX_PIECE = 2048  # ticks: keeps a rounded jerk's effect inside a piece below 10^-2 step
ZERO = (Fraction(0), Fraction(0), Fraction(0))


class FitError(RuntimeError):
    """The chain cannot follow the wanted motion (a speed above one step per tick, an acceleration
    the firmware cannot hold)."""


@dataclass(frozen=True)
class Span:
    """`ticks` ticks over which each axis's wanted advance is one polynomial (axis index → Poly)."""

    ticks: int
    advance: tuple[Poly, ...]


def at(poly: Poly, k: int) -> Fraction:
    """The advance over tick k (k ≥ 1)."""
    a, b, g = poly
    return a + b * (k - 1) + g * choose2(k - 1)


def shifted(poly: Poly, skip: int) -> Poly:
    """The same advance over the ticks after the first `skip`."""
    a, b, g = poly
    return a + b * skip + g * choose2(skip), b + g * skip, g


def travel(poly: Poly, m: int) -> Fraction:
    a, b, g = poly
    return m * a + choose2(m) * b + choose3(m) * g


def sign(x: Fraction | int) -> int:
    return (x > 0) - (x < 0)


def as_direction(s: int) -> Direction:
    """A sign known to be ±1 (a moving advance's, or a state's direction) as a direction."""
    return 1 if s > 0 else -1


def piece_sign(poly: Poly, m: int) -> int:
    """The direction of an advance that keeps one sign over ticks 1..m (0: none)."""
    a, b, g = poly
    middle = (m + 1) // 2
    vertex = [round(1.5 - float(b / g))] if g else []
    for k in (1, m, middle, *vertex):
        if 1 <= k <= m and (s := sign(at(poly, k))):
            return s
    return 0


def sign_changes(poly: Poly, m: int) -> list[int]:
    """Ticks k in 2..m where the advance takes the sign opposite to the last nonzero one before
    it."""
    a, b, g = poly
    if not (a or b or g):
        return []
    candidates = {1, m}
    # A(k) = g/2·(k−1)(k−2) + b·(k−1) + a: its real roots (and its vertex) bracket every change of
    # sign
    qa, qb, qc = float(g) / 2, float(b) - 1.5 * float(g), float(a) - float(b) + float(g)
    roots: list[float] = []
    if qa != 0.0:
        roots.append(-qb / (2 * qa))
        disc = qb * qb - 4 * qa * qc
        if disc >= 0:
            roots += [(-qb - math.sqrt(disc)) / (2 * qa), (-qb + math.sqrt(disc)) / (2 * qa)]
    elif qb != 0.0:
        roots.append(-qc / qb)
    for root in roots:
        if 0 <= root <= m + 1:
            base = math.floor(root)
            candidates.update(k for k in (base - 1, base, base + 1, base + 2) if 1 <= k <= m)
    ticks = sorted(candidates)
    changes = []
    last = 0
    for k in ticks:
        s = sign(at(poly, k))
        if s and last and s != last:
            changes.append(k)
        last = s or last
    return changes


def fit_window(
    chain: CubicChain, spans: Sequence[Span], exact_end: Sequence[AxisState] | None = None
) -> tuple[list[CubicSegment], list[int]]:
    """Cubic segments that run `spans` from `chain` (moved on past them), and each axis's steps
    (signed).

    The last tick lands every axis's ideal on the wanted one; with `exact_end` also its speed and
    acceleration (the chain then equals a planned chain after the window, which carries on from
    it)."""
    count = chain.axis_count
    dev = [Fraction(0)] * count  # chain's ideal − wanted ideal, per axis, in 2^-31 step
    made = [0] * count
    out: list[CubicSegment] = []
    total = sum(s.ticks for s in spans)
    if total < 1:
        raise FitError("an empty window")
    done = 0
    for span in spans:
        ticks = span.ticks - (1 if done + span.ticks == total else 0)  # the last tick lands
        cuts = sorted(
            {
                0,
                ticks,
                *range(MAX_PIECE, ticks, MAX_PIECE),
                *(k - 1 for p in span.advance for k in sign_changes(p, ticks) if ticks),
            }
        )
        for lo, hi in zip(cuts, cuts[1:]):
            piece = [shifted(p, lo) for p in span.advance]
            out.append(_piece(chain, piece, hi - lo, dev, made))
        done += span.ticks
    last = spans[-1]
    wanted = [at(p, last.ticks) for p in last.advance]
    out.append(_landing(chain, wanted, dev, made, exact_end))
    return out, made


def _piece(
    chain: CubicChain, piece: list[Poly], m: int, dev: list[Fraction], made: list[int]
) -> CubicSegment:
    axes: list[CubicAxis] = []
    for axis, poly in enumerate(piece):
        state = chain.axes[axis]
        s = piece_sign(poly, m)
        if s == 0 and not any(poly):
            if not state.at_rest:
                axes.append(CubicAxis(axis=axis, speed=0, accel=0, direction=state.direction))
            continue
        s = s or state.direction
        a, b, g = (s * x for x in poly)
        jerk = round(g)
        u = s * dev[axis]
        wanted = m * a + choose2(m) * b + choose3(m) * g
        i, d = _round_state(a, b, jerk, wanted, u, m, axis, s * at(poly, m))
        if state.direction == s and state.i == i and state.d == d:
            if jerk:
                axes.append(CubicAxis(axis=axis, jerk=jerk))
        else:
            axes.append(
                CubicAxis(axis=axis, speed=i, accel=d, direction=as_direction(s), jerk=jerk or None)
            )
        dev[axis] += s * (m * i + choose2(m) * d + choose3(m) * jerk - wanted)
    segment = CubicSegment(n=m, axes=tuple(axes))
    _advance(chain, segment, made)
    return segment


def _round_state(
    a: Fraction,
    b: Fraction,
    jerk: int,
    wanted: Fraction,
    u: Fraction,
    m: int,
    axis: int,
    end: Fraction,
) -> tuple[int, int]:
    """Integer speed and acceleration for a piece of m ticks (jerk given): the chain's ideal ends at
    most m quanta ahead of the wanted one (u: how far ahead it starts), its last advance near the
    wanted `end`, and every advance within 0 … 1 step."""
    # the real (i, d) that give the wanted distance and the wanted last advance with this jerk
    if m > 1:
        c2, c3, e2 = choose2(m), choose3(m), choose2(m - 1)
        rest_x, rest_a = wanted - u - c3 * jerk, end - e2 * jerk
        d_real = (rest_x - m * rest_a) / (c2 - m * (m - 1))
    else:
        d_real = b
    centre = round(d_real)
    for d in sorted(
        {centre + k for k in range(-3, 4)} | {math.floor(b), math.ceil(b)},
        key=lambda d: abs(d - d_real),
    ):
        if not (abs(d) < CUBIC_ACCEL_LIMIT and abs(d + m * jerk) < CUBIC_ACCEL_LIMIT):
            continue
        first = math.ceil((wanted - choose2(m) * d - choose3(m) * jerk - u) / m)
        for i in (first, first + 1, first + 2):
            if 0 <= i < SIGMA and advances_in_range(i, d, jerk, m):
                return i, d
    raise FitError(
        f"axis {axis}: an advance of {float(a) / SIGMA:.4f} step per tick (change "
        f"{float(b) / SIGMA:.3g}) cannot be held within 0 … 1 step per tick over {m} ticks"
    )


def _landing(
    chain: CubicChain,
    wanted: list[Fraction],
    dev: list[Fraction],
    made: list[int],
    exact_end: Sequence[AxisState] | None,
) -> CubicSegment:
    """One tick that puts every axis's ideal exactly on the wanted one."""
    axes: list[CubicAxis] = []
    for axis, want in enumerate(wanted):
        state = chain.axes[axis]
        step = want - dev[axis]  # the absolute advance that lands exactly
        if step.denominator != 1:
            raise FitError(f"axis {axis}: the window does not end on the quantum grid")
        advance = int(step)
        end = exact_end[axis] if exact_end is not None else None
        if advance == 0 and (end is None or end.at_rest) and state.at_rest and not dev[axis]:
            continue
        s = sign(advance) or (end.direction if end is not None else state.direction)
        speed, accel, jerk = abs(advance), 0, 0
        if end is not None and not end.at_rest:
            if end.direction != s:
                raise FitError(f"axis {axis}: the window ends turning around")
            accel = end.i - speed
            jerk = end.d - accel
        axes.append(
            CubicAxis(
                axis=axis, speed=speed, accel=accel, direction=as_direction(s), jerk=jerk or None
            )
        )
        dev[axis] = Fraction(0)
    segment = CubicSegment(n=1, axes=tuple(axes))
    _advance(chain, segment, made)
    return segment


def _advance(chain: CubicChain, segment: CubicSegment, made: list[int]) -> None:
    for step in chain.advance(segment):
        made[step.axis] += step.start.direction * step.steps


__all__ = [
    "FitError",
    "Span",
    "at",
    "piece_sign",
    "fit_window",
    "shifted",
    "sign_changes",
    "travel",
]
