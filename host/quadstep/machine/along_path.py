"""A stop along the path (HOLD_ALONG, PROTOCOL.md §5.1).

Each axis of a HOLD decelerates on its own, at its own rate, so where the axes move at different
speeds they stop at different times and the tool leaves the line it was cutting. The segments of a
straight stretch move every axis at speeds in one proportion; decelerations in that proportion
(the axis that takes longest to stop keeping its own, every other one less) stop them together, on
the line. The board takes them only where the hold begins in one of those segments, which the host
cannot know in advance, so it is told which.

A quadratic segment carries its speeds; a jerk-limited (cubic) one carries only what changes, so
its speeds come from the firmware's chain, followed here over every segment a motion sends.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..link import AlongPath
from ..protocol import CubicSegment, Segment
from ..protocol.cubic_run import SpeedChain

# Done counts travel mod 2^16: a run never names more segments than that.
MAX_RUN = 0xFFFF
# A quadratic segment's speed (1/4096 step per tick) in the chain's unit, 2^-31 step per tick.
QUADRATIC_UNIT = 19
# How far apart two quadratic segments' speeds on an axis may be, in units of their 16-bit speeds,
# once scaled to the same speed on the fastest axis, and still count as one direction: each speed
# is rounded on its own.
ROUNDING = 2
# The S-curve planner rounds each axis's jerks on its own, so the axes of a straight move keep their
# proportion only to that rounding (half a percent on a slow axis): a cubic segment's speeds count
# as one direction with another's within 1/128 of the fastest, each.
CUBIC_SPREAD = 7


@dataclass(frozen=True)
class Speeds:
    """A segment's speed on each axis, the larger of its start and end, signed by its direction, in
    2^-31 step per tick; `slack`, how far each may lie from the line's proportion."""

    values: tuple[int, ...]
    slack: int


def quadratic_speeds(segment: Segment, axis_count: int) -> Speeds | None:
    """A quadratic segment's speeds; None when nothing moves."""
    out = [0] * axis_count
    for move in segment.axes:
        if move.axis < axis_count:
            out[move.axis] = move.direction * (max(move.v0, move.vn) << QUADRATIC_UNIT)
    return Speeds(tuple(out), ROUNDING << QUADRATIC_UNIT) if any(out) else None


def same_direction(a: Speeds, b: Speeds) -> bool:
    """Whether speeds `a` and `b` point the same way: on every axis, in the same proportion to the
    fastest axis of `a`, within their slack."""
    x, y = a.values, b.values
    ref = max(range(len(x)), key=lambda axis: abs(x[axis]))
    if x[ref] * y[ref] <= 0:
        return False
    tolerance = a.slack * abs(y[ref]) + b.slack * abs(x[ref])
    return all(
        (p > 0) == (q > 0) and (p < 0) == (q < 0) and abs(p * y[ref] - q * x[ref]) <= tolerance
        for p, q in zip(x, y)
    )


def path_decels(w: Sequence[int], decels: Sequence[int]) -> tuple[int, ...]:
    """Decelerations in proportion to the speeds `w` (one per firmware axis, 0 for a still axis):
    the axis with the largest |w| / decel (the first of equals) keeps its own, every other moving
    axis gets decel[lead] * |w| / |w[lead]| rounded down (at least 1, at most its own); a still
    axis keeps its own."""
    size = [abs(v) for v in w]
    lead = 0
    for axis in range(len(size)):
        if size[axis] * decels[lead] > size[lead] * decels[axis]:
            lead = axis
    return tuple(
        max(1, decels[lead] * size[axis] // size[lead]) if size[axis] else decels[axis]
        for axis in range(len(size))
    )


class SegmentSource(Protocol):
    """What a motion streams from (motion.Segments), as far as a stop along the path reads it."""

    def segment(self, i: int) -> Segment | CubicSegment: ...


def sent_items(
    segments: SegmentSource, index: int, count: int, message: object
) -> Sequence[Segment | CubicSegment]:
    """The `count` segments from `index` that a frame, `message`, sent: the frame itself where it
    is one segment's, else read from `segments`."""
    if isinstance(message, (Segment, CubicSegment)):
        return (message,)
    return [segments.segment(index + j) for j in range(count)]


class PathSpeeds:
    """The speeds of the segments a motion has sent, numbered from its first: a quadratic segment's
    read from it, a cubic one's kept as it is sent, from the firmware's chain followed over every
    segment from rest (a motion begins with the machine at rest, and goes on with the same chain
    after go_on())."""

    def __init__(self, axis_count: int) -> None:
        self.axis_count = axis_count
        self._chain = SpeedChain.at_rest(axis_count)
        self._cubic: dict[int, Speeds] = {}
        self._kept_from = 0

    def sent(self, k: int, items: Sequence[Segment | CubicSegment], done: int) -> None:
        """Segments `k`, k + 1, … sent; those before `done` have run and are let go of."""
        for j, item in enumerate(items):
            if isinstance(item, CubicSegment):
                start = self._start(item)
                self._chain.follow(item)
                end = self._signed()
                values = tuple(p if abs(p) >= abs(q) else q for p, q in zip(start, end))
                if any(values):
                    self._cubic[k + j] = Speeds(values, max(map(abs, values)) >> CUBIC_SPREAD)
            else:
                self._chain.follow(item)
        for old in range(self._kept_from, done):
            self._cubic.pop(old, None)
        self._kept_from = max(self._kept_from, done)

    def _signed(self) -> tuple[int, ...]:
        chain = self._chain
        return tuple((i or 0) * d for i, d in zip(chain.i, chain.direction))

    def _start(self, segment: CubicSegment) -> tuple[int, ...]:
        """The speeds `segment` starts at: the chain's, and those it sets."""
        out = list(self._signed())
        for a in segment.axes:
            if a.speed is not None and a.axis < self.axis_count:
                out[a.axis] = a.direction * a.speed
        return tuple(out)

    def reader(self, segments: SegmentSource, first: int) -> Callable[[int], Speeds | None]:
        """Segment i's speeds (`segments`' numbering, the motion's first being `first`)."""

        def speeds(i: int) -> Speeds | None:
            segment = segments.segment(i)
            if isinstance(segment, Segment):
                return quadratic_speeds(segment, self.axis_count)
            return self._cubic.get(i - first)

        return speeds


def along_path(
    speeds: Callable[[int], Speeds | None],
    running: int,
    sent: int,
    done_count: int,
    decels: Sequence[int],
) -> AlongPath | None:
    """For a HOLD while segment `running` runs, the board's done count then being `done_count`,
    with the segments before `sent` sent (`speeds` reads each one's): the run of segments from
    `running` on whose speeds point its way, and the decelerations that stop them on that line
    (from the run's fastest segment, whose speeds are the finest). None where that segment's speeds
    are not known or nothing moves: the HOLD then stops each axis at its own."""
    if not running < sent:
        return None
    w = speeds(running)
    if w is None:
        return None
    best, end = w, running + 1
    while end < min(sent, running + MAX_RUN):
        v = speeds(end)
        if v is None or not same_direction(w, v):
            break
        if max(map(abs, v.values)) > max(map(abs, best.values)):
            best = v
        end += 1
    last = done_count + end - running - 1
    return AlongPath(path_decels(best.values, decels), done_count & 0xFFFF, last & 0xFFFF)
