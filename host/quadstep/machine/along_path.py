"""A stop along the path (HOLD_ALONG, PROTOCOL.md §5.1).

Each axis of a HOLD decelerates on its own, at its own rate, so where the axes move at different
speeds they stop at different times and the tool leaves the line it was cutting. The segments of a
straight stretch move every axis at speeds in one proportion; decelerations in that proportion
(the axis that takes longest to stop keeping its own, every other one less) stop them together, on
the line. The board takes them only where the hold begins in one of those segments, which the host
cannot know in advance, so it is told which.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from ..link import AlongPath
from ..protocol import CubicSegment, Segment

# Done counts travel mod 2^16: a run never names more segments than that.
MAX_RUN = 0xFFFF
# How far apart, in units of the 16-bit speeds, two segments' speeds on an axis may be, once scaled
# to the same speed on the fastest axis, and still count as one direction: each speed is rounded on
# its own.
ROUNDING = 2


class SegmentSource(Protocol):
    """What a motion streams from (motion.Segments), as far as a stop along the path reads it."""

    def segment(self, i: int) -> Segment | CubicSegment: ...


def speeds(segment: Segment, axis_count: int) -> tuple[int, ...] | None:
    """Each axis's larger speed of the segment's start and end, signed by its direction; None when
    nothing moves."""
    out = [0] * axis_count
    for move in segment.axes:
        if move.axis < axis_count:
            out[move.axis] = move.direction * max(move.v0, move.vn)
    return tuple(out) if any(out) else None


def same_direction(a: Sequence[int], b: Sequence[int]) -> bool:
    """Whether speeds `a` and `b` point the same way: on every axis, in the same proportion to the
    fastest axis of `a`, within the speeds' rounding."""
    ref = max(range(len(a)), key=lambda axis: abs(a[axis]))
    if a[ref] * b[ref] <= 0:
        return False
    tolerance = ROUNDING * (abs(a[ref]) + abs(b[ref]))
    return all(
        (x > 0) == (y > 0) and (x < 0) == (y < 0) and abs(x * b[ref] - y * a[ref]) <= tolerance
        for x, y in zip(a, b)
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


def along_path(
    segments: SegmentSource, running: int, sent: int, done_count: int, decels: Sequence[int]
) -> AlongPath | None:
    """For a HOLD while segment `running` of `segments` runs, the board's done count then being
    `done_count`, with the segments before `sent` sent: the run of segments from `running` on
    whose speeds point its way, and the decelerations that stop them on that line (from the
    run's fastest segment, whose speeds are the finest). None where that segment is not
    quadratic (a jerk-limited one) or moves nothing: the HOLD then stops each axis at its own."""
    axis_count = len(decels)
    if not running < sent:
        return None
    first = segments.segment(running)
    w = speeds(first, axis_count) if isinstance(first, Segment) else None
    if w is None:
        return None
    best, end = w, running + 1
    while end < min(sent, running + MAX_RUN):
        nxt = segments.segment(end)
        v = speeds(nxt, axis_count) if isinstance(nxt, Segment) else None
        if v is None or not same_direction(w, v):
            break
        if max(map(abs, v)) > max(map(abs, best)):
            best = v
        end += 1
    last = done_count + end - running - 1
    return AlongPath(path_decels(best, decels), done_count & 0xFFFF, last & 0xFFFF)
