"""Which frame sends the next segments of a plan: chained in SEGMENTS or CUBIC_SEGMENTS where the
board has them and the chain is known, else one segment alone (PROTOCOL.md §5.2)."""

from __future__ import annotations

from typing import Protocol, TypeVar

from .cubic import CubicSegment
from .cubic_run import CubicSegments
from .cubic_run import pack as cubic_pack
from .raster import Raster, RasterLine
from .segment import Segment
from .segment_run import RUN_LIMIT, RunChain, Segments, pack


def run_limit(queue_capacity: int) -> int:
    """Segments a host puts in one SEGMENTS frame for a board with this queue: half of it (so the
    next frame is taken while the other half runs), at most RUN_LIMIT."""
    return max(1, min(RUN_LIMIT, queue_capacity // 2))


class SegmentSource(Protocol):
    """A plan's segments by index (planner/segments.py, planner/stream.py)."""

    def segment(self, i: int) -> Segment | CubicSegment: ...


def next_frame(
    source: SegmentSource,
    index: int,
    end: int,
    chain: RunChain,
    limit: int,
    cubic_runs: bool = True,
    quadratic_runs: bool = True,
) -> Segment | CubicSegment | Segments | CubicSegments | Raster:
    """The frame that sends segment `index` and what follows it before `end`: segments of its kind
    chained into SEGMENTS or CUBIC_SEGMENTS (at most `limit`; 0 where the firmware has no SEGMENTS,
    cubic ones only with `cubic_runs`, quadratic ones only with `quadratic_runs`) once the chain is
    known, else segment `index` alone, as
    its own message (with a limit of 1 too: after a lost frame the board keeps later single-segment
    frames, never a run); `chain` moves on past what the frame sends."""
    first = source.segment(index)
    if isinstance(first, RasterLine):  # a laser line: its own frame, read against the chain
        chain.follow(first)
        return first.raster
    if isinstance(first, CubicSegment):
        cubics = _run(first, source, index, end, limit)
        assert chain.speeds is not None
        cubic = cubic_pack(cubics, chain.speeds, limit) if limit > 1 and cubic_runs else None
        if cubic is None:
            chain.follow_cubic(first)
            return first
        chain.forget()
        return cubic
    run = _run(first, source, index, end, limit)
    packed = pack(run, chain, limit) if limit > 1 and quadratic_runs else None
    if packed is None:
        chain.follow(first)
        return first
    return packed


Kind = TypeVar("Kind", Segment, CubicSegment)


def _run(first: Kind, source: SegmentSource, index: int, end: int, limit: int) -> list[Kind]:
    """`first` (segment `index`) and the segments of its kind right after it, before `end`: at most
    `limit` in all."""
    run = [first]
    for i in range(index + 1, min(end, index + limit)):
        segment = source.segment(i)
        if not isinstance(segment, type(first)) or isinstance(segment, RasterLine):
            break
        run.append(segment)
    return run
