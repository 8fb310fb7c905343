"""A job's OUTPUTS (spindle, laser, coolant) where its stream sends them, and switched off when it
stops early."""

from __future__ import annotations

from bisect import bisect_left

from ..link import Link, LinkError
from ..planner.outputs import OFF
from ..planner.plan import Plan
from ..protocol import Output, Outputs
from .motion import MotionEnd
from .takeups import StreamPlan

FEED_HOLD = "feed hold"  # how a motion held to rest with the rest of the job kept ends


def stream_outputs(plan: Plan | StreamPlan) -> list[tuple[int, int, Outputs]]:
    """The plan's OUTPUTS at the places of the stream (a take-up's segments run with the move they
    are in)."""
    if not isinstance(plan, StreamPlan):
        return plan.outputs
    stream, planned = plan.segments, len(plan.base)
    return [
        (bisect_left(stream.origin, index) if index < planned else len(stream), section, message)
        for index, section, message in plan.base.outputs
    ]


def outputs_at(plan: Plan | StreamPlan, index: int) -> Outputs | None:
    """The OUTPUTS the board runs under at item `index` of the plan's stream (the last sent at or
    before it); None when the plan sets none before it."""
    sent = [message for at, _, message in stream_outputs(plan) if at <= index]
    return sent[-1] if sent else None


def spindle_stopped(message: Outputs) -> Outputs:
    """`message` with the spindle (or laser) off and the coolant as it is."""
    return Outputs(outputs=message.outputs & int(Output.FLOOD | Output.MIST), power=0)


def switch_off(link: Link, end: MotionEnd, outputs: bool) -> MotionEnd:
    """A job stopped before its end leaves the spindle, laser and coolant off (a feed hold keeps
    them)."""
    if end.ended_by in ("done", FEED_HOLD) or not outputs:
        return end
    try:
        link.send(OFF)
        link.drain(timeout=2)
    except LinkError as exc:
        return (
            end
            if end.error
            else MotionEnd(
                end.ended_by,
                end.position,
                end.segments_done,
                end.stop_event_ns,
                end.held,
                end.hold_tick,
                error=f"outputs not switched off: {exc}",
            )
        )
    return end
