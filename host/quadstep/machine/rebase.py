"""A long open job lets go of what the board has run: from a segment boundary the board is past, its
plan, its stream with the take-ups and the machine's record of them begin again there (a rolling
leg), so that a file of millions of lines, or a sender's endless stream, runs in bounded memory
(job.py, docs/PLANNER.md "Streaming"). Where that boundary is inside a move, the plan begins with
the rest of that move, its move 0.

Only where the stream runs the boundary's planned segment as planned and no axis has a take-up to
make before its next motion, so that the take-ups of the stream from there, worked out again from
the band and the firmware's chain there, are those it has. A jerk-limited plan begins again only
where one of its parts began (an addition went on from there: its S-curve planner's state there is
kept, `Plan.scurve_starts`), and only while its stream has no take-ups."""

from __future__ import annotations

from array import array
from bisect import bisect_left, bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..backlash.base import from_arrays
from ..backlash.compensate import Compensated
from ..kernel.cubic_chain import CubicChain
from ..kernel.engine_model import predict
from ..planner.plan import Plan
from ..planner.scurve_state import ScurveState
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from .takeups import StreamPlan

# A job lets go of what ran once the board is this many segments into its plan: each time costs a
# copy of what is kept (a few thousand segments), so not at every addition.
REBASE_SEGMENTS = 4000
# Segment boundaries looked at, back from the board's segment, for one to begin again at.
TRIES = 256


@dataclass(frozen=True)
class Rebase:
    """Where a plan begins again: at its planned segment `segment`, after its first `moves` moves
    (the move under way there, if any, is the new plan's move 0), at item `index` of its stream,
    `ticks` motion ticks and `motor` steps (take-ups included) from its start."""

    segment: int
    moves: int
    index: int
    ticks: int
    motor: tuple[int, ...]


def find(plan: Plan | StreamPlan, ticks: Sequence[int], upto: int) -> Rebase | None:
    """The last segment boundary of `plan` at or before its stream item `upto`, after its first
    move, where the plan may begin again (`ticks`: the stream's cumulative ticks); None when there
    is none, or it lets go of fewer than REBASE_SEGMENTS."""
    base = plan.base if isinstance(plan, StreamPlan) else plan
    if upto >= REBASE_SEGMENTS and base.config.jerk_limited:
        return _find_part_start(plan, ticks, upto)
    if (
        upto < REBASE_SEGMENTS
        or not isinstance(base.segments, SegmentArrays)
        or not base.end_ideal2
        or len(base.junctions) <= base.moves
    ):
        return None
    origin = plan.segments.origin_of(upto) if isinstance(plan, StreamPlan) else upto
    first_end = base.move_ends[0] if base.moves else len(base.segments)
    steps = from_arrays(base.segments).steps
    moving = _moving(steps)
    for segment in range(origin, max(origin - TRIES, first_end - 1), -1):
        index = _stream_index(plan, segment)
        if index is None or index > upto:
            continue
        if index < REBASE_SEGMENTS:
            return None
        if isinstance(plan, StreamPlan) and _takes_up(plan, moving, segment, int(ticks[index])):
            continue
        motor = steps[:segment].sum(axis=0)
        if isinstance(plan, StreamPlan):
            for takeup in plan.compensated.takeups:
                if takeup.start < ticks[index]:
                    motor[takeup.axis] += takeup.steps
        moves = bisect_right(base.move_ends, segment)  # ending at or before it
        return Rebase(segment, moves, index, int(ticks[index]), tuple(int(m) for m in motor))
    return None


def _find_part_start(plan: Plan | StreamPlan, ticks: Sequence[int], upto: int) -> Rebase | None:
    """The last place where a part of the jerk-limited `plan` began, at or before its stream item
    `upto` (None where there is none, it lets go of fewer than REBASE_SEGMENTS, or the stream has
    take-ups)."""
    base = plan.base if isinstance(plan, StreamPlan) else plan
    if isinstance(plan, StreamPlan) and (plan.compensated.takeups or plan.compensated.windows):
        return None
    for start in reversed(base.scurve_starts):
        index = _stream_index(plan, start.segments)
        if index is None or index > upto:
            continue
        if index < REBASE_SEGMENTS:
            return None
        motor = tuple(p - s for p, s in zip(start.position, base.start))
        return Rebase(start.segments, start.move, index, int(ticks[index]), motor)
    return None


def _stream_index(plan: Plan | StreamPlan, segment: int) -> int | None:
    """The stream item that runs base segment `segment` as planned; None where a take-up runs
    there."""
    if not isinstance(plan, StreamPlan):
        return segment
    stream = plan.segments
    index = bisect_left(stream.origin, segment)
    return index if index < len(stream) and stream.ref[index] == segment else None


def _moving(steps: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per axis: the planned segments that step it (`steps`: theirs, per axis), and their
    directions."""
    found = []
    for axis in range(steps.shape[1]):
        moves = np.flatnonzero(steps[:, axis])
        found.append((moves, np.sign(steps[moves, axis])))
    return found


def _takes_up(
    plan: StreamPlan, moving: list[tuple[np.ndarray, np.ndarray]], segment: int, tick: int
) -> bool:
    """Some axis has a take-up to make before its first motion from planned segment `segment` on
    (at motion tick `tick`): the stream from there would not begin as it did."""
    band = plan.compensated.band_at(tick)
    for axis, (moves, directions) in enumerate(moving[: len(band.axes)]):
        next_move = int(np.searchsorted(moves, segment))
        if next_move < moves.size and band.axes[axis].take(int(directions[next_move])):
            return True
    return False


def entry_chain(plan: StreamPlan, index: int) -> CubicChain:
    """The firmware's chain before item `index` of the stream (where no take-up runs)."""
    stream, compensated = plan.segments, plan.compensated
    count = stream.axis_count
    windows = [w for w in compensated.windows if w.first + w.count <= index]
    if windows:  # from the last take-up before it
        window = windows[-1]
        chain = window.chain.copy()
        predict(stream.segments(window.first, window.first + window.count), None, 0, count, chain)
        begin = window.first + window.count
    else:
        chain = compensated.entry.copy() if compensated.entry else CubicChain(count)
        begin = 1 if len(stream) and stream.ref[0] < 0 else 0  # after the anchor: at rest, e = 0
    if begin >= index:
        return chain
    # planned segments from there on: each axis as the last one naming it left it
    assert isinstance(stream.base, SegmentArrays)
    first, last = stream.ref[begin], stream.ref[index - 1]
    part = _arrays_from(stream.base, first, last + 1)
    return from_arrays(part, chain).chain_before(len(part))


def rebased(plan: Plan | StreamPlan, at: Rebase) -> Plan | StreamPlan:
    """`plan` from `at` on."""
    if not isinstance(plan, StreamPlan):
        return _plan_from(plan, at)
    base = _plan_from(plan.base, at)
    shift = at.segment
    stream = _stream_from(plan.segments, at.index, base.segments, shift)
    n = plan.base.segments.n
    planned = int(np.frombuffer(n, np.dtype(n.typecode))[:shift].sum(dtype=np.int64))
    compensated = _compensated_from(plan.compensated, stream, at, planned)
    if base.scurve_starts:  # the firmware's chain where the part began (no take-up before it)
        compensated.entry = base.scurve_starts[0].chain.copy()
    else:
        compensated.entry = entry_chain(plan, at.index)
    return StreamPlan(plan.config, stream, compensated.pauses, compensated, base)


def _plan_from(plan: Plan, at: Rebase) -> Plan:
    """`plan` from its segment `at.segment` on (its start the steppers there)."""
    first, move = at.segment, at.moves
    pauses = [(i - first, line) for i, line in plan.pauses if i >= first]
    dropped = len(plan.pauses) - len(pauses)
    # what the board runs under there, kept at the start (a feed hold may stop the spindle)
    before = [(0, 0, message) for at, _, message in plan.outputs if at <= first][-1:]
    after = [(at - first, section - dropped, m) for at, section, m in plan.outputs if at > first]
    rest = replace(
        plan,
        pauses=pauses,
        moves=plan.moves - move,
        move_ends=array("i", (e - first for e in plan.move_ends[move:])),
        outputs=before + after,
        junctions=plan.junctions[move:],
    )
    if isinstance(plan.segments, Stream):
        return _scurve_from(rest, plan.segments, at)
    segments = plan.segments
    made = from_arrays(_arrays_from(segments, 0, first)).steps.sum(axis=0)
    return replace(
        rest,
        segments=_arrays_from(segments, first, len(segments)),
        start=tuple(int(s + m) for s, m in zip(plan.start, made)),
    )


def _scurve_from(rest: Plan, segments: Stream, at: Rebase) -> Plan:
    """The jerk-limited plan `rest` (its segments `segments`, the rest of it so far) from where its
    part that began at `at` did: that part's state is its start, moving."""
    start = next(s for s in rest.scurve_starts if s.move == at.moves)

    def shifted(state: ScurveState) -> ScurveState:
        return replace(
            state,
            move=state.move - start.move,
            segments=state.segments - start.segments,
            distance_mm=state.distance_mm - start.distance_mm,
        )

    return replace(
        rest,
        segments=segments.tail(at.segment),
        start=start.position,
        distance_mm=rest.distance_mm - start.distance_mm,
        scurve_states=tuple(shifted(s) for s in rest.scurve_states),
        scurve_starts=tuple(shifted(s) for s in rest.scurve_starts if s.move >= start.move),
    )


def _arrays_from(segments: SegmentArrays, first: int, stop: int) -> SegmentArrays:
    """Segments `first` … `stop` − 1."""
    count = segments.axis_count
    return SegmentArrays(
        count,
        segments.n[first:stop],
        segments.axes[first:stop],
        segments.v0[first * count : stop * count],
        segments.vn[first * count : stop * count],
        segments.r[first * count : stop * count],
        segments.line[first:stop],
    )


def _stream_from(stream: Stream, index: int, base: SegmentArrays | Stream, shift: int) -> Stream:
    """`stream` from its item `index` on, over `base` (its base from segment `shift` on)."""
    refs = np.frombuffer(stream.ref, np.int32)[index:]
    extras = refs[refs < 0]
    first_extra = int(-extras.max() - 1) if extras.size else len(stream.extra)
    # a base segment's index moves down by `shift`; an extra's by the extras let go of
    moved = np.where(refs >= 0, refs - shift, refs + first_extra).astype(np.int32)
    origin = np.frombuffer(stream.origin, np.int32)[index:] - shift
    return Stream(
        base,
        ref=array("i", moved.tobytes()),
        extra=stream.extra[first_extra:],
        n=stream.n[index:],
        line=stream.line[index:],
        origin=array("i", origin.astype(np.int32).tobytes()),
    )


def _compensated_from(
    compensated: Compensated, stream: Stream, at: Rebase, planned: int
) -> Compensated:
    """The take-ups of `compensated` from `at` on, in `stream` (that far on); `planned`: the
    plan's ticks before `at` without the take-ups."""
    return Compensated(
        stream,
        compensated.band_at(at.ticks),
        compensated.band_end,
        takeups=[
            replace(t, start=t.start - at.ticks, planned=t.planned - planned)
            for t in compensated.takeups
            if t.start >= at.ticks
        ],
        windows=[
            replace(
                w,
                first=w.first - at.index,
                start=w.start - at.ticks,
                motor=tuple(m - d for m, d in zip(w.motor, at.motor)),
            )
            for w in compensated.windows
            if w.first >= at.index
        ],
        pauses=[(i - at.index, line) for i, line in compensated.pauses if i >= at.index],
        added_ticks=compensated.added_ticks,
    )
