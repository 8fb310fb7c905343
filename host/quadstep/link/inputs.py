"""The inputs' procedures (PROTOCOL.md §5.4): their state, a motion that ends at an input's edge,
and waiting for rest after a hold the firmware began itself.

A PROBE arms an input; the segments that follow run until it reaches its level. At that tick the
firmware latches every position (EVENT INPUT, cause TRIGGER) and holds, which restarts the stream as
a HOLD does (a thread waiting in Link.send raises Stopped; the frames in flight are refused, BUSY,
and not resent); HOLD_DONE follows at rest. If the motion comes to rest first, EVENT PROBE_MISSED
says where. Homing and probing are both this one procedure.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence

from ..protocol import (
    CubicSegment,
    HoldDone,
    InputCause,
    InputChange,
    Inputs,
    InputStatus,
    Probe,
    ProbeMissed,
    Segment,
    State,
    StatusReport,
)
from .connection import Link
from .errors import LinkTimeout, Stopped, status_alarm


def input_status(link: Link) -> InputStatus:
    """The inputs' state and settings now (INPUTS)."""
    return link.request(Inputs(), InputStatus)


def until_input(
    link: Link,
    probe: Probe,
    segments: Iterable[Segment | CubicSegment],
    timeout: float | None = None,
) -> InputChange | ProbeMissed:
    """Stream `segments` (a motion from rest to rest, after any that lead up to it: a backlash
    take-up, which moves the motors only) with `probe` armed for the last motion, and wait for its
    end: at the armed edge (returns that EVENT INPUT, once the hold after it has come to rest) or at
    rest without it (returns PROBE_MISSED).

    The board reports PROBE_MISSED wherever it comes to rest with its queue empty, so what leads up
    to the armed motion runs first, unarmed, and the PROBE follows once it is at rest: armed
    before, a host that paused between the two (a busy computer) would leave the board at rest
    there, its PROBE spent, and the motion after it would run unarmed into the input.

    Raises FirmwareError if the PROBE is refused (INPUT_AT_LEVEL: the input is there already; BUSY:
    not at rest), AlarmError if an alarm (a hard limit on another input, the abort button) ends the
    motion, LinkTimeout after `timeout` seconds."""
    deadline = None if timeout is None else time.monotonic() + timeout
    armed = lead_up(link, list(segments), timeout)
    holds, missed, triggers = (
        link.report_count(HoldDone),
        link.report_count(ProbeMissed),
        link.holds_by_input,
    )
    stream = link.generation  # the edge ends it: a segment sent after that would open another
    link.send(probe, timeout, stream)
    try:
        for segment in armed:
            link.send(segment, timeout, stream)
    except Stopped:
        if link.holds_by_input == triggers:
            raise  # a STOP or HOLD from elsewhere
    end: InputChange | ProbeMissed
    while True:
        generation = link.generation
        try:
            if link.holds_by_input == triggers:
                report = link.wait_report(ProbeMissed, missed, generation, _slice(link, deadline))
                if report is not None:
                    end = report
                    break
            elif link.wait_report(HoldDone, holds, generation, _slice(link, deadline)) is not None:
                end = next(c for c in reversed(link.input_changes) if c.cause == InputCause.TRIGGER)
                break
        except Stopped:
            if link.holds_by_input == triggers:
                raise  # a STOP or HOLD from elsewhere
            continue  # the edge came while waiting: wait for its hold
        # a board gone silent does not answer; an alarm's report may be lost
        alarm = status_alarm(link.status())
        if alarm is not None:
            raise alarm
        if deadline is not None and time.monotonic() >= deadline:
            raise LinkTimeout(
                f"the motion after PROBE {probe.input.name} did not end within {timeout:g} s"
            )
    wait_rest(link, timeout)
    return end


def lead_up(
    link: Link, segments: Sequence[Segment | CubicSegment], timeout: float | None
) -> Sequence[Segment | CubicSegment]:
    """Run what leads up to the last motion of `segments` (unarmed, to rest); that motion."""
    first = last_motion(segments)
    if first:
        stream = link.generation  # a hold from elsewhere (the feed hold button) ends it
        for segment in segments[:first]:
            link.send(segment, timeout, stream)
        link.wait_idle(timeout, stream)
    return segments[first:]


def last_motion(segments: Sequence[Segment | CubicSegment]) -> int:
    """Where the last motion from rest begins: after the last segment before the end whose every
    axis ends at rest (0 when there is none). Quadratic segments only mark a rest: a cubic one's end
    speeds are the chain's."""
    for i in range(len(segments) - 1, 0, -1):
        before = segments[i - 1]
        if isinstance(before, Segment) and not any(move.vn for move in before.axes):
            return i
    return 0


def wait_rest(link: Link, timeout: float | None = None) -> StatusReport:
    """Wait until nothing moves (a hold the firmware began itself included) and adopt the firmware's
    sequence state; returns its status."""
    deadline = None if timeout is None else time.monotonic() + timeout
    generation = link.generation
    while True:
        status = link.status()
        if status.state not in (State.RUNNING, State.HOLDING):
            break
        if deadline is not None and time.monotonic() >= deadline:
            raise LinkTimeout(f"firmware still {status.state.name} after {timeout:g} s")
        time.sleep(0.005)
    link.resync(status, generation)
    return status


def _slice(link: Link, deadline: float | None) -> float:
    return (
        link.poll_interval
        if deadline is None
        else max(0.0, min(link.poll_interval, deadline - time.monotonic()))
    )
