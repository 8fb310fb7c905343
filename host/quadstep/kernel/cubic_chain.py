"""The firmware's chain of cubic state (docs/CUBIC.md, firmware/core/qs_cubic.c): per axis, in its
direction of motion and in 2^-31 step, e the ideal ahead of the stepper, i the next advance, d its
change per tick. It checks a cubic segment exactly as the firmware does (the same fields, in the
same order) and advances exactly, so a chain of any length is followed without drift."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from .fixed import CUBIC_ACCEL_LIMIT, CUBIC_SHIFT, HALF, MAX_AXES, SIGMA
from .motion import Cubic, Direction, Quadratic

RefusedField = Literal["AXES", "ACCEL", "SPEED"]  # the field the firmware's ERROR would name


def choose2(n: int) -> int:
    return n * (n - 1) // 2


def choose3(n: int) -> int:
    return n * (n - 1) * (n - 2) // 6


class CubicRefused(ValueError):
    """A cubic segment the firmware would refuse: the field and axis it names."""

    def __init__(self, field: RefusedField, axis: int | None, detail: str) -> None:
        super().__init__(detail)
        self.field = field
        self.axis = axis


@dataclass
class AxisState:
    """One axis of the chain: exact integers (i may be out of range: the next segment is then
    refused)."""

    e: int = 0
    i: int = 0
    d: int = 0
    direction: Direction = 1

    @property
    def at_rest(self) -> bool:
        return self.i == 0 and self.d == 0


def advances_in_range(i: int, d: int, r: int, n: int) -> bool:
    """0 ≤ I(k) ≤ Σ for k = 1..n (the ends, and the extreme where the differences change sign)."""
    end = i + (n - 1) * d + choose2(n - 1) * r
    return 0 <= i <= SIGMA and 0 <= end <= SIGMA and extreme_in_range(i, d, r, n)


def extreme_in_range(i: int, d: int, r: int, n: int) -> bool:
    """0 ≤ I(k) ≤ Σ where the advance turns inside k = 1..n (its ends are checked apart)."""
    if r > 0 and d < 0:
        k = 1 + (-d + r - 1) // r
    elif r < 0 and d > 0:
        k = 1 + (d - r - 1) // -r
    else:
        return True
    return k >= n or 0 <= i + (k - 1) * d + choose2(k - 1) * r <= SIGMA


@dataclass
class CubicStep:
    """What one axis does in one segment: its start state, jerk and steps (in its direction)."""

    axis: int
    start: AxisState
    r: int
    steps: int


@dataclass
class CubicChain:
    """The firmware's chain of cubic state, axis by axis."""

    axis_count: int = MAX_AXES
    axes: list[AxisState] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.axes:
            self.axes = [AxisState() for _ in range(self.axis_count)]

    def reset(self) -> None:
        """At rest on the ideal: after STOP, a hold, an alarm."""
        self.axes = [AxisState() for _ in range(self.axis_count)]

    def copy(self) -> CubicChain:
        return CubicChain(
            self.axis_count, [AxisState(a.e, a.i, a.d, a.direction) for a in self.axes]
        )

    def follow_quadratic(self, seg: Quadratic, totals: dict[int, int]) -> None:
        """The exact end state of a quadratic segment; `totals` its steps per axis."""
        for axis, a in enumerate(self.axes):
            a.d = 0
            mv = next((m for m in seg.axes if m.axis == axis), None)
            if mv is None:
                a.i = 0
                continue
            a.e = (mv.r + seg.n * (mv.v0 + mv.vn) - 8192 * totals[axis]) << 18
            a.i = mv.vn << 19
            a.direction = mv.direction

    def starts(self, seg: Cubic) -> list[tuple[AxisState, int]]:
        """Each axis's start state and jerk for `seg` (sets applied), without changing the chain."""
        named = {a.axis: a for a in seg.axes}
        out = []
        for axis, a in enumerate(self.axes):
            start = AxisState(a.e, a.i, a.d, a.direction)
            m = named.get(axis)
            r = 0
            if m is not None:
                if m.speed is not None:
                    if m.direction != a.direction:
                        start.e = -start.e
                    start.direction = m.direction
                    start.i, start.d = m.speed, m.accel
                r = m.jerk or 0
            out.append((start, r))
        return out

    def check(self, seg: Cubic) -> None:
        """Raise CubicRefused as the firmware would: AXES, then ACCEL for every axis, then SPEED."""
        named = [a.axis for a in seg.axes]
        if any(a >= self.axis_count for a in named):
            raise CubicRefused("AXES", None, f"axes {named}, firmware has {self.axis_count}")
        starts = self.starts(seg)
        n = seg.n
        for axis, (s, r) in enumerate(starts):
            if not (
                -CUBIC_ACCEL_LIMIT < s.d < CUBIC_ACCEL_LIMIT
                and -CUBIC_ACCEL_LIMIT < s.d + n * r < CUBIC_ACCEL_LIMIT
            ):
                raise CubicRefused(
                    "ACCEL",
                    axis,
                    f"axis {axis}: acceleration {s.d} … {s.d + n * r} leaves 24 bits",
                )
        for axis, (s, r) in enumerate(starts):
            if (s.i or s.d or r) and not advances_in_range(s.i, s.d, r, n):
                raise CubicRefused(
                    "SPEED", axis, f"axis {axis}: the advance per tick leaves 0 … 1 step"
                )

    def advance(self, seg: Cubic) -> list[CubicStep]:
        """Check `seg`, move the chain past it, and return what every moving axis does."""
        self.check(seg)
        n = seg.n
        out = []
        for axis, (s, r) in enumerate(self.starts(seg)):
            a = self.axes[axis]
            a.direction = s.direction
            if s.at_rest and not r:
                a.e, a.i, a.d = s.e, 0, 0
                continue
            travel = n * s.i + choose2(n) * s.d + choose3(n) * r
            total = s.e + travel + HALF
            steps = total >> CUBIC_SHIFT
            a.e = (total & (SIGMA - 1)) - HALF
            a.i = s.i + n * s.d + choose2(n) * r
            a.d = s.d + n * r
            out.append(CubicStep(axis, s, r, steps))
        return out


__all__ = [
    "AxisState",
    "CubicChain",
    "CubicRefused",
    "CubicStep",
    "RefusedField",
    "advances_in_range",
    "choose2",
    "choose3",
    "extreme_in_range",
]
