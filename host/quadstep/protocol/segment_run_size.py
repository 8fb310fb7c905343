"""The bytes a quadratic plan takes on the wire, from its arrays, without building a frame.

It follows `frames.next_frame` and `segment_run.pack` decision for decision (the first segment
alone, as the chain is not known yet; then SEGMENTS frames of canonical records, each frame filled
up to its record limit or its payload), but with the sizes worked out from the columns: what each
record carries (n, the axes byte, start, residual and change fields in zigzag varints, a REPEAT)
depends on the segment before and the chain it leaves, which are arithmetic on the arrays. Only
the MIRROR choice depends on the frame's start, so the fill is one short loop over the records.
tests/planner/test_wire_count.py holds the count equal to the encoded frames'.
"""

from __future__ import annotations

import numpy as np

from ..kernel.fixed import D
from .constants import MAX_FRAME
from .segment_run import PAYLOAD_MAX, SEGMENTS_MAX

# type and seq, the CRC-16, COBS's one code byte (a frame is far below 254 bytes), the delimiter
FRAME_OVERHEAD = 6
assert MAX_FRAME + 2 < 254


def _varint_bytes(values: np.ndarray) -> np.ndarray:
    """Bytes of each value as a zigzag varint (one byte for −64 … 63, else two)."""
    return np.where((values >= -64) & (values <= 63), 1, 2)


def quadratic_wire_bytes(columns: dict[str, np.ndarray], axis_count: int, limit: int) -> int:
    """Bytes on the wire for segments given as columns n, axes (S,) and v0, vn, r (S, axes), sent
    with at most `limit` records a SEGMENTS frame (≤ 1: one SEGMENT a frame)."""
    n = columns["n"].astype(np.int64)
    count = len(n)
    if count == 0:
        return 0
    axes = columns["axes"].astype(np.int64)
    shift = np.arange(axis_count)
    named = (axes[:, None] >> shift) & 1 == 1
    active = named.sum(axis=1)
    single = FRAME_OVERHEAD + 3 + 6 * active  # a SEGMENT: n, the axes byte, v0 vn r per axis
    if limit <= 1:
        return int(single.sum())
    v0 = columns["v0"].astype(np.int64)
    vn = columns["vn"].astype(np.int64)
    r = columns["r"].astype(np.int64)
    sign = np.where((axes[:, None] >> (4 + shift)) & 1 == 1, -1, 1)
    # the chain after each segment: named axes at vn with their exact residual, the others still
    travel = r + n[:, None] * (v0 + vn)
    rest = sign * (travel - 2 * D * ((travel + D) // (2 * D)))
    rows = np.where(named, np.arange(count)[:, None], -1)
    last_named = np.maximum.accumulate(rows, axis=0)  # the segment that last named each axis
    residual_after = np.take_along_axis(rest, np.maximum(last_named, 0), axis=0)
    known_after = last_named >= 0
    speed_after = np.where(named, vn, 0)
    # against the chain before each segment (the first has none: it goes alone)
    residual_before = np.vstack([np.zeros((1, axis_count), np.int64), residual_after[:-1]])
    known_before = np.vstack([np.zeros((1, axis_count), bool), known_after[:-1]])
    speed_before = np.vstack([np.zeros((1, axis_count), np.int64), speed_after[:-1]])
    chained = np.all(~named | (known_before & (sign * residual_before == r)), axis=1)
    start = np.where(named, v0 - speed_before, 0)
    start_bytes = np.where(
        np.any(start != 0, axis=1), np.where(named, _varint_bytes(start), 0).sum(axis=1), 0
    )
    residual_bytes = np.where(chained, 0, np.where(named, _varint_bytes(r), 0).sum(axis=1))
    change = np.where(named, vn - v0, 0)
    plain_bytes = np.where(named, _varint_bytes(change), 0).sum(axis=1)
    same_axes = np.concatenate([[False], axes[1:] == axes[:-1]])
    same_shape = (
        same_axes
        & np.concatenate([[False], n[1:] == n[:-1]])
        & np.concatenate([[False], np.all((v0[1:] == v0[:-1]) & (vn[1:] == vn[:-1]), axis=1)])
    )
    fixed = 2 + start_bytes + residual_bytes  # head and n's low byte, start and residual fields
    return int(single[0]) + _fill_frames(
        limit,
        (fixed.tolist(), plain_bytes.tolist(), change.tolist()),
        ((same_shape & chained).tolist(), same_axes.tolist(), named.tolist()),
    )


def _fill_frames(
    limit: int,
    sizes: tuple[list[int], list[int], list[list[int]]],
    flags: tuple[list[bool], list[bool], list[list[bool]]],
) -> int:
    """Segments 1… into frames as `segment_run.pack` fills them; their bytes."""
    fixed, plain, change = sizes
    repeats, same_axes, named = flags
    most = min(limit, SEGMENTS_MAX)
    total, i, count = 0, 1, len(fixed)
    while i < count:
        size = records = 0
        last = [0] * len(change[0])  # each axis's last change in the frame (for MIRROR)
        while i < count and records < most:
            if records and repeats[i]:
                length = 1
            else:
                length = fixed[i] + (0 if records and same_axes[i] else 1)
                length += _change_bytes(plain[i], change[i], named[i], last)
            if size + length > PAYLOAD_MAX:
                break
            size += length
            records += 1
            for axis, c in enumerate(change[i]):
                if c:
                    last[axis] = c
            i += 1
        total += size + FRAME_OVERHEAD
    return total


def _change_bytes(plain: int, change: list[int], named: list[bool], last: list[int]) -> int:
    """The vn fields' bytes: none for a cruise, else plain or mirrored (each named axis's change
    plus its last in the frame), whichever is shorter."""
    if not any(change):
        return 0
    if not any(last):
        return plain
    mirrored = sum(1 if -64 <= c + m <= 63 else 2 for c, m, k in zip(change, last, named) if k)
    return min(plain, mirrored)


__all__ = ["FRAME_OVERHEAD", "quadratic_wire_bytes"]
