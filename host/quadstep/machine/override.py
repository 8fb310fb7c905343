"""The overrides (planner/feed_override.py: feed, rapid, spindle) on a running job: its rest
planned again from a move boundary not yet sent. The residual chain, the steppers and every axis's
speed there are the plan's own and the first move is entered at the speed the plan had there, so
the new tail follows the sent segments without a stop and every move still lands exactly
(docs/PLANNER.md, "Feed override")."""

from __future__ import annotations

import time
from array import array
from bisect import bisect_left
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..give_way import give_way
from ..kernel.fixed import D
from ..planner.feed_override import scale_feeds
from ..planner.plan import Boundary, Plan, plan_program
from ..planner.program import JobError, LinearMove, Program
from ..planner.scurve_rest import continue_scurve, replan_scurve_from
from ..planner.scurve_state import ScurveState
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from .motion import Motion
from .move_items import MoveItems
from .remainder import move_item, rest_of
from .takeups import StreamPlan

TRIES = 12  # boundaries tried, one after another, before the change waits for the next stop


def _signs(axes: np.ndarray, count: int) -> np.ndarray:
    """Each segment's direction per axis (±1) from its axes byte."""
    bits = axes.astype(np.int64)[:, None]
    return np.where((bits >> (4 + np.arange(count))) & 1, -1, 1)


def boundary_at(plan: Plan, move: int) -> Boundary:
    """The state of the quadratic `plan` where its move `move` (≥ 1) begins: the ideal summed over
    every segment before, the last segment's speeds, the look-ahead's entry speed."""
    segments = plan.segments
    assert isinstance(segments, SegmentArrays)
    index, count = plan.move_ends[move - 1], segments.axis_count
    arrays = segments.numpy()
    # the chain's travel over the segments before the boundary, or back from the end over those
    # after it (fewer, near the end of a long plan)
    span = slice(index, None) if plan.end_ideal2 else slice(0, index)
    travel = (
        _signs(arrays["axes"][span], count)
        * arrays["n"][span].astype(np.int64)[:, None]
        * (arrays["v0"][span].astype(np.int64) + arrays["vn"][span])
    ).sum(axis=0)
    if plan.end_ideal2:
        ideal2 = np.asarray(plan.end_ideal2, dtype=np.int64) - travel
    else:
        ideal2 = 2 * D * np.asarray(plan.start, dtype=np.int64) + travel
    exits = (
        _signs(arrays["axes"][index - 1 : index], count)[0]
        * arrays["vn"][index - 1].astype(np.int64)
        if index
        else np.zeros(count, np.int64)
    )
    return Boundary(
        tuple(int(i) for i in ideal2), tuple(int(v) for v in exits), plan.junctions[move]
    )


def join(plan: Plan, move: int, tail: Plan) -> Plan:
    """`plan` up to where its move `move` begins, then `tail`: the whole job as it runs."""
    a, t = plan.segments, tail.segments
    assert isinstance(a, SegmentArrays) and isinstance(t, SegmentArrays)
    index, count = plan.move_ends[move - 1], a.axis_count
    out = SegmentArrays(
        count,
        a.n[:index] + t.n,
        a.axes[:index] + t.axes,
        a.v0[: index * count] + t.v0,
        a.vn[: index * count] + t.vn,
        a.r[: index * count] + t.r,
        a.line[:index] + t.line,
    )
    pauses = [p for p in plan.pauses if p[0] < index]
    outputs = [o for o in plan.outputs if o[0] < index]
    for at, section, message in tail.outputs:
        if not (at == 0 and outputs and outputs[-1][2] == message):  # as they are already
            outputs.append((at + index, section + len(pauses), message))
    return replace(
        plan,
        segments=out,
        end=tail.end,
        pauses=pauses + [(i + index, line) for i, line in tail.pauses],
        moves=move + tail.moves,
        max_landing_error=max(plan.max_landing_error, tail.max_landing_error),
        move_ends=plan.move_ends[:move] + array("i", (e + index for e in tail.move_ends)),
        retries=plan.retries + tail.retries,
        outputs=outputs,
        junctions=plan.junctions[:move] + tail.junctions,
        end_ideal2=tail.end_ideal2,
    )


# the rest of a program, beginning at the given stepper positions, at the overrides wanted now
Scaler = Callable[[Program, tuple[int, ...]], Program]


def feeds_at(percent: int) -> Scaler:
    """The feeds at `percent` % (rapids and S as they are)."""
    return lambda program, _start: scale_feeds(program, percent)


def replan_from(
    program: Program,
    plan: Plan,
    move: int,
    scale: Scaler,
    label: str,
    items: MoveItems | None = None,
) -> Plan:
    """`plan` (of `program`) up to where its move `move` begins, then the rest of `program` scaled
    by `scale` (the overrides), going on from there (what lies between the moves, a dwell or a
    pause, comes with the rest). `items`: where the plan's moves are in the program, kept from
    before."""
    boundary = boundary_at(plan, move)
    rest = _rest_after(program, plan, move, items)
    give_way()  # planned onto a running job: the link's threads first
    tail = plan_program(scale(rest, boundary.position), plan.config, label=label, boundary=boundary)
    return join(plan, move, tail)


def _first_after(program: Program, plan: Plan, move: int, items: MoveItems | None) -> int:
    """The first item of `program` after the one its plan's move `move` − 1 came from; `items`:
    where the plan's moves are in the program, kept from before."""
    if move == 0:
        return 0
    if items is None:
        return move_item(program, plan.config, plan.start, move - 1) + 1
    return items.item_of(program, move - 1) + 1


def _rest_after(program: Program, plan: Plan, move: int, items: MoveItems | None) -> Program:
    """`program` from its first item after its plan's move `move` − 1 (the outputs in force
    there first)."""
    first = _first_after(program, plan, move, items)
    return rest_of(program, first) if items is None else items.rest_of(program, first)


def continue_plan(
    program: Program,
    plan: Plan,
    state: ScurveState,
    scale: Scaler,
    label: str,
    items: MoveItems | None = None,
) -> Plan:
    """The jerk-limited `plan` up to `state` (one its S-curve planner kept), then the rest of
    `program` (lines added to it) scaled by `scale`, going on from that state."""
    rest = _rest_after(program, plan, state.move, items)
    return continue_scurve(plan, state, scale(rest, state.position), label)


def replan_scurve(
    program: Program,
    plan: Plan,
    move: int,
    scale: Scaler,
    planned: Scaler,
    label: str,
    items: MoveItems | None = None,
) -> Plan:
    """The jerk-limited `plan` (of `program` scaled by `planned`) up to where its move `move`
    begins, planned again from where the part it is in began, then the rest of `program` scaled by
    `scale`, going on from there."""
    begun = next((s for s in reversed(plan.scurve_starts) if s.move <= move), None)
    before, start = (
        (program, plan.start)
        if begun is None
        else (_rest_after(program, plan, begun.move, items), begun.position)
    )
    first = _first_after(program, plan, move, items)
    previous = program.items[first - 1]
    assert isinstance(previous, LinearMove)
    here = plan.config.to_steps(previous.target)
    rest = rest_of(program, first) if items is None else items.rest_of(program, first)
    return replan_scurve_from(plan, begun, planned(before, start), move, scale(rest, here), label)


def first_difference(old: Stream, new: Stream) -> int:
    """The first item where the streams differ (their own segments, or another base's); the
    shorter's length when none does."""
    count = min(len(old), len(new))
    a, b = np.frombuffer(old.ref, np.int32)[:count], np.frombuffer(new.ref, np.int32)[:count]
    n_old, n_new = np.frombuffer(old.n, np.uint32)[:count], np.frombuffer(new.n, np.uint32)[:count]
    for i in np.flatnonzero((a != b) | (a < 0) | (n_old != n_new)):
        if (
            n_old[i] != n_new[i]
            or a[i] >= 0
            or b[i] >= 0
            or old.extra[-a[i] - 1] != new.extra[-b[i] - 1]
        ):
            return int(i)
    return count


@dataclass(frozen=True)
class Swap:
    """The job planned again: stream it from item `index` on, after the running plan's items before
    it."""

    index: int
    plan: Plan | StreamPlan


# the machine's: a plan with its take-ups, as one running
Restreamer = Callable[[Plan, StreamPlan], StreamPlan]


def prepare(
    program: Program,
    running: Plan | StreamPlan,
    after: int,
    before: int,
    scale: Scaler,
    label: str,
    restream: Restreamer | None,
    planned: Scaler | None = None,
    items: MoveItems | None = None,
) -> Swap | None:
    """`running` planned again with `scale` from the first move boundary where the new stream
    leaves the old at or after its item `after` (and before item `before`, the section's end); None
    when there is none. A jerk-limited plan is planned again whole for an override (its moves
    before the boundary as they were: `planned` is how its program was scaled), and goes on from
    the first state it kept that is not sent for lines added (`planned` None)."""
    base = running.base if isinstance(running, StreamPlan) else running
    scurve = base.config.jerk_limited
    added = scurve and planned is None  # lines added: from a state the plan kept
    if len(base.junctions) <= base.moves or (
        (added and not base.scurve_states)
        if scurve
        else not isinstance(base.segments, SegmentArrays)
    ):
        return None  # not made by plan_program
    origin = running.segments.origin_of(after) if isinstance(running, StreamPlan) else after
    move = bisect_left(base.move_ends, origin) + 1
    boundaries: Sequence[int] = range(move, min(move + TRIES, base.moves))
    states = {s.move: s for s in base.scurve_states if s.move >= move}
    if added:  # only where a state was kept and is not sent yet
        boundaries = sorted(states)[:TRIES]
    for move in boundaries:
        try:
            if added:
                joined = continue_plan(program, base, states[move], scale, label, items)
            elif scurve:
                assert planned is not None
                joined = replan_scurve(program, base, move, scale, planned, label, items)
            else:
                joined = replan_from(program, base, move, scale, label, items)
        except JobError:
            continue  # no whole-tick profile from this boundary: the next one
        at = base.move_ends[move - 1]
        swapped: Plan | StreamPlan
        if not isinstance(running, StreamPlan) or restream is None:
            index, swapped = at, joined
        else:
            # with the take-ups again: the new stream goes on from where it leaves the old one (a
            # take-up across the boundary begins before it)
            swapped = restream(joined, running)
            # where the new stream leaves the old, at the latest where the new rest begins
            index = min(
                first_difference(running.segments, swapped.segments),
                bisect_left(swapped.segments.origin, at),
            )
        if index >= before:
            return None
        if index < after:
            continue  # sent already
        return Swap(index, swapped)
    return None


def replan_running(
    program: Program,
    running: Plan | StreamPlan,
    motion: Motion,
    scale: Scaler,
    label: str,
    restream: Restreamer | None,
    ticks: Sequence[int],
    start_at: int = 0,
    planned: Scaler | None = None,
    items: MoveItems | None = None,
) -> Swap | None:
    """`running` planned again with `scale` from the first move boundary that `motion` (streaming
    it) has not sent (and not before item `start_at`), and the motion cut there. A boundary sent
    meanwhile is passed by for one twice as far ahead as the planning took. None when the section
    under way has no boundary left (or the motion ends)."""
    after, hz = max(motion.first + motion.sent, start_at), running.config.tick_hz
    for _ in range(TRIES):
        if motion.end is not None:
            return None
        began = time.monotonic()
        swap = prepare(program, running, after, motion.last, scale, label, restream, planned, items)
        if swap is None:
            return None
        if motion.cut(swap.index):
            return swap
        sent = min(motion.first + motion.sent, len(ticks) - 1)
        after = max(
            swap.index + 1, bisect_left(ticks, ticks[sent] + 2.0 * (time.monotonic() - began) * hz)
        )
    return None
