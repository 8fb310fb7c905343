"""The bytes a jerk-limited plan takes on the wire, without building a frame.

It follows `frames.next_frame` and `cubic_run.pack` decision for decision — the plan's first
(quadratic, at rest) segment alone as a SEGMENT, then CUBIC_SEGMENTS frames filled up to their
record limit or their payload, a segment whose set cannot start from the chain alone as a
CUBIC_SEGMENT —
with each record's size worked out in plain integers (its jerk codes, n and flags, the sets'
speed changes and accelerations, the given jerks, in varints) and the chain's speeds carried as
`cubic_run.SpeedChain` carries them. tests/protocol/test_segment_run_size.py holds the count equal
to the encoded frames'.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..kernel.cubic_chain import choose2
from ..kernel.fixed import MAX_AXES, SIGMA
from .cubic import CubicSegment
from .cubic_run import ACCEL, PAYLOAD_MAX, RECORDS_MAX, SETS
from .segment import Segment
from .segment_run_size import FRAME_OVERHEAD


def _uvarint_bytes(u: int) -> int:
    return max(1, (u.bit_length() + 6) // 7)


def _zigzag_bytes(value: int) -> int:
    return _uvarint_bytes(value << 1 if value >= 0 else (-value << 1) - 1)


class _Speeds:
    """Per axis the chain's I, d (None: unknown) and direction, as SpeedChain has them."""

    def __init__(self, axis_count: int) -> None:
        self.i: list[int | None] = [None] * axis_count
        self.d: list[int | None] = [None] * axis_count
        self.direction = [1] * axis_count

    def follow_quadratic(self, segment: Segment) -> None:
        moves = {a.axis: a for a in segment.axes}
        for axis in range(len(self.i)):
            move = moves.get(axis)
            self.i[axis], self.d[axis] = (move.vn << 19, 0) if move is not None else (0, 0)
            if move is not None:
                self.direction[axis] = move.direction

    def follow(self, segment: CubicSegment) -> None:
        named = {a.axis: a for a in segment.axes}
        n = segment.n
        for axis in range(len(self.i)):
            a = named.get(axis)
            r = 0
            if a is not None:
                if a.speed is not None:
                    self.i[axis], self.d[axis] = a.speed, a.accel
                    self.direction[axis] = a.direction
                r = a.jerk or 0
            i, d = self.i[axis], self.d[axis]
            if i is not None and d is not None:
                self.i[axis] = i + n * d + choose2(n) * r
                self.d[axis] = d + n * r

    def base(self, axis: int, direction: int) -> int | None:
        i = self.i[axis]
        if i is None or not 0 <= i <= SIGMA:
            return None
        return 0 if i == 0 else i if direction == self.direction[axis] else -i


def _record_bytes(segment: CubicSegment, chain: _Speeds, last: list[int]) -> int | None:
    """The size of `segment`'s record from `chain` (`last` moved on), or None where a set cannot
    start from the chain."""
    size = 1  # the jerk codes
    sets = accels = 0
    for a in segment.axes:
        if a.speed is None:
            continue
        base = chain.base(a.axis, a.direction)
        if base is None or not -(1 << 31) <= a.speed - base < 1 << 31:
            return None
        sets += 1
        size += _zigzag_bytes(a.speed - base)
        accels += _zigzag_bytes(a.accel)
    with_accels = any(a.accel for a in segment.axes if a.speed is not None)
    if sets:
        size += 1 + (accels if with_accels else 0)  # the sets byte, the accelerations
    for a in segment.axes:
        jerk = a.jerk or 0
        if jerk:
            if jerk != last[a.axis] and jerk != -last[a.axis]:
                size += _zigzag_bytes(jerk)
            last[a.axis] = jerk
    flags = (SETS if sets else 0) | (ACCEL if with_accels else 0)
    return size + _uvarint_bytes(segment.n << 2 | flags)


def _single_bytes(segment: CubicSegment) -> int:
    """A CUBIC_SEGMENT: n, the fields byte, 7 bytes a set, 2 a jerk."""
    return (
        FRAME_OVERHEAD
        + 3
        + sum(
            (7 if a.speed is not None else 0) + (2 if a.jerk is not None else 0)
            for a in segment.axes
        )
    )


def cubic_wire_bytes(
    segments: Sequence[Segment | CubicSegment], axis_count: int, limit: int
) -> int | None:
    """Bytes on the wire for a jerk-limited plan's segments (cubic ones after at most one
    quadratic first), at most `limit` records a CUBIC_SEGMENTS frame (≤ 1: one CUBIC_SEGMENT a
    frame); None for a stream of another shape (count it by its frames)."""
    chain = _Speeds(axis_count)
    total, index = 0, 0
    if segments and isinstance(segments[0], Segment):
        first = segments[0]
        total += FRAME_OVERHEAD + 3 + 6 * len(first.axes)  # alone: the chain is not known yet
        chain.follow_quadratic(first)
        index = 1
    cubic: list[CubicSegment] = []
    for segment in segments[index:]:
        if not isinstance(segment, CubicSegment):
            return None
        cubic.append(segment)
    most = min(limit, RECORDS_MAX)
    at = 0
    while at < len(cubic):
        size = records = 0
        last = [0] * MAX_AXES
        while limit > 1 and at + records < len(cubic) and records < most:
            kept = list(last)
            length = _record_bytes(cubic[at + records], chain, last)
            if length is None or size + length > PAYLOAD_MAX:
                last[:] = kept
                break
            size += length
            chain.follow(cubic[at + records])
            records += 1
        if records:
            total += size + FRAME_OVERHEAD
            at += records
        else:
            total += _single_bytes(cubic[at])
            chain.follow(cubic[at])
            at += 1
    return total


__all__ = ["cubic_wire_bytes"]
