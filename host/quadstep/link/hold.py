"""The HOLD procedure (PROTOCOL.md §5.1): a controlled stop to rest, with the exact rest position.

HOLD restarts the stream like STOP (every unsent and unacknowledged frame is
dropped, a thread waiting in Link.send raises Stopped), then the firmware
decelerates every moving axis and reports EVENT HOLD_DONE. A hold may take
long, so the firmware is asked how it is going every `poll_interval`; once
it is no longer holding, a HOLD_DONE lost on the wire is asked for again by
repeating the HOLD (at rest the firmware repeats its report).

A HOLD_ALONG stops along the path: the host gives, besides the HOLD's decelerations, those that
stop the axes of a straight run of segments together on their line, and the board takes them where
the hold begins in one of those segments (machine/along_path.py works them out).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from concurrent.futures import Future
from dataclasses import dataclass

from ..kernel.fixed import DECEL_MAX, MAX_AXES
from ..protocol import Capability, ErrorCode, Hold, HoldAlong, HoldDone, State, StatusReport
from ..protocol.wire import four_axes
from .connection import Link
from .errors import AlarmError, FirmwareError, LinkError, LinkTimeout


@dataclass(frozen=True)
class AlongPath:
    """Decelerations (one per firmware axis) that stop the segments whose done count (the board's
    segments_done while each runs, mod 2^16) lies in `first` … `last` together on their line."""

    decels: tuple[int, ...]
    first: int
    last: int


def hold_message(decels: Sequence[int], axis_count: int) -> Hold:
    """The HOLD for `decels` (one per firmware axis, or one for all); a bad value is a ValueError
    naming the axis and the limit, before anything is sent."""
    values = list(decels)
    if len(values) == 1:
        values *= axis_count
    if len(values) != axis_count:
        raise ValueError(
            f"hold needs 1 or {axis_count} decelerations (one per axis), got {len(values)}"
        )
    for axis, d in enumerate(values):
        if not isinstance(d, int) or not 1 <= d <= DECEL_MAX:
            raise ValueError(
                f"hold deceleration of axis {axis} is {d!r}; limit 1..{DECEL_MAX} "
                "(in 1/2^24 step per tick²)"
            )
    return Hold(decel=four_axes(values + [0] * (MAX_AXES - axis_count)))


def hold(
    link: Link,
    decels: Sequence[int],
    timeout: float | None = None,
    along: AlongPath | None = None,
) -> HoldDone:
    """Decelerate every moving axis to rest and discard the queue; returns the HOLD_DONE event.

    With `along` (to a board that stops along the path: Capability.STOPS_ALONG) a HOLD_ALONG: where
    the hold begins in one of its segments the board takes `along.decels`, and the event is a
    HoldDoneAlong.

    `decels`: per axis (or one for all) in 1/2^24 step per tick², 1..8191 (at 50 kHz one unit is
    about 149 steps/s²). The event gives `hold_tick` (the motion tick at which the deceleration
    began), `motion_ticks` (when the last axis stopped) and the rest positions;
    engine_model.predict_hold reproduces every step in between. Raises AlarmError if the firmware
    is or goes into ALARM instead (for a hold that found the queue run dry while moving),
    LinkTimeout after `timeout` seconds.
    """
    message: Hold | HoldAlong = hold_message(decels, link.axis_count)
    identity = link.identity
    if (
        along is not None
        and identity is not None
        and identity.capabilities & Capability.STOPS_ALONG
    ):
        path = hold_message(along.decels, link.axis_count)
        message = HoldAlong(
            decel=message.decel,
            path_decel=path.decel,
            first=along.first & 0xFFFF,
            last=along.last & 0xFFFF,
        )
    seen = link.report_count(HoldDone)
    try:
        _, generation = link.restart(message)
    except FirmwareError as exc:
        if exc.report.code == ErrorCode.ALARM_ACTIVE:
            raise _alarm_error(link) from exc
        raise
    done = _wait_hold_done(link, message, seen, generation, timeout)
    # the queue is empty now: adopt its free slots and counts
    link.resync(link.status(), generation)
    return done


def hold_async(link: Link, decels: Sequence[int], timeout: float | None = None) -> Future[HoldDone]:
    """hold() in a thread of its own: returns at once with a Future of the HOLD_DONE event."""
    message = hold_message(decels, link.axis_count)  # bad input is refused here, not in the thread
    future: Future[HoldDone] = Future()

    def run() -> None:
        try:
            future.set_result(hold(link, message.decel[: link.axis_count], timeout))
        except BaseException as exc:  # handed to whoever waits on the future
            future.set_exception(exc)

    threading.Thread(target=run, name="quadstep-hold", daemon=True).start()
    return future


def _alarm_error(link: Link) -> LinkError:
    alarm = link.last_alarm
    return (
        AlarmError(alarm)
        if alarm is not None
        else LinkError("firmware is in ALARM; a STOP clears it (Ctrl+X in the TUI)")
    )


def _wait_hold_done(
    link: Link, message: Hold | HoldAlong, seen: int, generation: int, timeout: float | None
) -> HoldDone:
    deadline = None if timeout is None else time.monotonic() + timeout
    while True:
        wait = (
            link.poll_interval
            if deadline is None
            else max(0.0, min(link.poll_interval, deadline - time.monotonic()))
        )
        done = link.wait_report(HoldDone, seen, generation, wait)
        if done is not None:
            return done
        if deadline is not None and time.monotonic() >= deadline:
            raise LinkTimeout(
                f"no HOLD_DONE within {timeout:g} s (the firmware may still be decelerating)"
            )
        status: StatusReport = link.status()
        if status.state == State.ALARM:
            raise _alarm_error(link)
        if (
            status.state != State.HOLDING
            and link.report_count(HoldDone) == seen
            and link.generation == generation
        ):
            # HOLD again: at rest it repeats HOLD_DONE
            link.request(message, StatusReport, status.next_seq)
