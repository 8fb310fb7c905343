"""One planned motion on its way to the board: streamed from a thread, halted by HOLD at any moment.

Jogs and jobs both run as a Motion. Streaming can keep the motion queued on
the board short (`lookahead_ticks`), so that a host that disappears leaves
little behind. halt() may be called from any thread: it sends HOLD, which
makes the board decelerate every moving axis to rest at the given
deceleration and discard the queued tail, and it returns the exact rest
position the board reports.
"""

from __future__ import annotations

import threading
import time
from bisect import bisect_left
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import accumulate, islice
from typing import Protocol

from ..kernel.fixed import DECEL_MAX
from ..link import AlarmError, AlongPath, Link, LinkError, Stopped, hold, wait_rest
from ..link.errors import status_alarm
from ..protocol import (
    AckReason,
    Capability,
    CubicSegment,
    HoldDone,
    HoldDoneAlong,
    IdentifyReply,
    InputCause,
    Outputs,
    Report,
    Segment,
)
from ..protocol.frame_choice import frame_choice
from ..protocol.frames import next_frame, run_limit
from ..protocol.messages import queue_slots
from ..protocol.raster import ring_fits
from ..protocol.segment_run import RunChain
from .along_path import PathSpeeds, along_path, sent_items

# Keep at least this many segments queued, whatever the lookahead, so the board
# always has the next one when a segment ends.
MIN_QUEUED_SEGMENTS = 2
# Segments beyond what the board's queue holds wait in the link's window, written by the link's
# reader as a report frees their slots, while the motion queued lasts less than AHEAD_S (and they
# take at most AHEAD_SLOTS): a queue of short segments (an Uno's 14 of about a millisecond) then
# outlasts this thread's wait for its turn in the interpreter.
AHEAD_S = 0.05
AHEAD_SLOTS = 64
SPACE_WAIT = 0.005  # s between checks while the lookahead is full
STALL_POLL = 0.25  # s without a completed segment before asking for STATUS
# how a motion ends whose queue ran dry while moving: the board stopped it (a hold), and the motion
# took it out of STARVED with HOLD, so it is IDLE at the end's position
STARVED = "starved"


@dataclass(frozen=True)
class MotionEnd:
    """How a motion ended and where the machine rests."""

    # "done", "error", "reset" (a STOP from elsewhere), STARVED, or the reason given to halt()
    ended_by: str
    position: tuple[int, ...]  # step positions at rest
    segments_done: int  # segments of this motion the board completed (before any hold)
    stop_event_ns: int | None = None  # time.monotonic_ns() when halt() was called
    held: bool = False  # brought to rest by HOLD (controlled deceleration)
    hold_tick: int | None = None  # motion tick at which the deceleration began
    error: str | None = None
    # halt()'s hold: the decelerations it used, one per firmware axis (along the path, or each
    # axis's own: engine_model.predict_hold reproduces every step from them and hold_tick)
    hold_decels: tuple[int, ...] | None = None


@dataclass(frozen=True)
class Rest:
    """Where a HOLD (or, without HOLD, a STOP) left the machine."""

    position: tuple[int, ...]
    held: bool
    hold_tick: int | None
    decels: tuple[int, ...] | None = None  # a HOLD's, one per firmware axis, as the board used them


def board_run_limit(identity: IdentifyReply) -> int:
    """Segments to put in one SEGMENTS or CUBIC_SEGMENTS frame to this board; 0 where its firmware
    takes neither (frame_choice says which of the two it is sent)."""
    runs = Capability.SEGMENTS | Capability.CUBIC_RUNS
    return run_limit(identity.queue_capacity) if identity.capabilities & runs else 0


class RunSize:
    """How many segments go in the next SEGMENTS frame: `limit` on a clean line. With less than
    `floor` ticks queued (at a start, or behind) the motion sends one segment a frame, each as soon
    as it is made. Once the link has had to write a frame again (or a frame was damaged either way),
    single SEGMENT frames for the next CALM frames: after a lost frame the board keeps the SEGMENT
    frames behind it (selective repeat) but never SEGMENTS, and a long frame is the likeliest to be
    damaged, so a noisy line runs as well as it did with one segment a frame."""

    CALM = 32

    def __init__(self, limit: int, link: Link, tick_hz: int) -> None:
        self.limit = limit
        self.link = link
        self.floor = tick_hz // 20  # 50 ms: with less queued, one segment a frame, out at once
        self.resent = self._trouble()
        self.calm = self.CALM

    def _trouble(self) -> int:
        """Signs of a noisy line so far: frames written again, ERRORs from the board, reports we
        could not read."""
        stats = self.link.stats
        return stats.retransmits + stats.errors + stats.decode_errors

    def next(self) -> int:
        resent = self._trouble()
        self.calm = 0 if resent != self.resent else self.calm + 1
        self.resent = resent
        return self.limit if self.calm >= self.CALM else min(self.limit, 1)


def fits_queue(queued: int, queued_ticks: int, board: IdentifyReply) -> bool:
    """Whether a frame may be sent whose last segment has `queued` segments not yet run before it,
    the motion to its end lasting `queued_ticks`: into the board's queue, or beyond it into the
    link's window while that motion lasts less than AHEAD_S."""
    return queued < board.queue_capacity or (
        queued < board.queue_capacity + AHEAD_SLOTS and queued_ticks < AHEAD_S * board.tick_hz
    )


def supports_hold(link: Link) -> bool:
    ident = link.identity
    return ident is not None and bool(ident.capabilities & Capability.HOLD)


def firmware_decels(link: Link, decels: Sequence[int]) -> tuple[int, ...]:
    """`decels` (the planned axes') for every axis the firmware has: the others stand still and
    get the largest."""
    return tuple(decels[: link.axis_count]) + (DECEL_MAX,) * (link.axis_count - len(decels))


def bring_to_rest(link: Link, decels: Sequence[int], along: AlongPath | None = None) -> Rest:
    """HOLD (HOLD_ALONG with `along`): decelerate every axis to rest and drop the queued tail;
    STOP where the firmware has no HOLD. `decels` covers the planned axes (firmware_decels)."""
    if supports_hold(link):
        per_axis = firmware_decels(link, decels)
        done = hold(link, per_axis, along=along)
        used = along.decels if along is not None and isinstance(done, HoldDoneAlong) else per_axis
        return Rest(tuple(done.position), True, done.hold_tick, used)
    status = link.stop()
    return Rest(tuple(status.position), False, None)


def running_sums(
    segments: Segments, first: int, last: int, index: int, ticks: list[int]
) -> list[int]:
    """The running sums of the ticks of `segments` from `first` up to `last`: those before `index`
    as `ticks` has them (the same segments), the rest made again."""
    sums = ticks[: index - first + 1]
    n = segments.n
    sums.extend(islice(accumulate((n[i] for i in range(index, last)), initial=sums[-1]), 1, None))
    return sums


class Segments(Protocol):
    """What a motion streams from: the planner's arrays, or a stream with take-ups
    (planner/stream.py)."""

    @property
    def axis_count(self) -> int: ...

    @property
    def n(self) -> Sequence[int]: ...  # each segment's ticks

    def __len__(self) -> int: ...

    def segment(self, i: int) -> Segment | CubicSegment: ...

    def pixels(self, i: int) -> int: ...  # the powers segment i carries (a RASTER line's)


class Motion:
    """Streams segments [first, last) of `segments`; start() it, then wait() or halt()."""

    def __init__(
        self,
        link: Link,
        segments: Segments,
        decels: Sequence[int],
        *,
        first: int = 0,
        last: int | None = None,
        lookahead_ticks: int | None = None,
        on_end: Callable[[MotionEnd], None] | None = None,
        outputs: Sequence[tuple[int, Outputs]] = (),
    ) -> None:
        self.link = link
        # called once, in the thread that ends the motion, before wait() returns
        self.on_end = on_end
        # the machine's view of the end, before that
        self.settle: Callable[[MotionEnd], MotionEnd] | None = None
        self.segments = segments
        self.decels = tuple(decels)
        self.first = first
        self.last = len(segments) if last is None else last
        self.lookahead_ticks = lookahead_ticks
        # (segment index, OUTPUTS): sent before that segment, or after the last; taken as sent
        self._outputs = deque(sorted(outputs, key=lambda o: o[0]))
        self._lock = threading.Lock()
        self._space = threading.Event()
        self._ended = threading.Event()
        self._end: MotionEnd | None = None
        self._halting: str | None = None
        self._sent = 0
        self._base_done = 0
        self._generation = 0  # the link's, when streaming began: a STOP from elsewhere changes it
        self._input_holds = 0  # holds the firmware began itself, when streaming began
        # streaming stops at `last`, moved down by cut(), and waits there for go_on()
        self._cut = False
        # go_on() renumbered the segments (`shift` not yet taken by the streaming thread): the
        # thread makes its running sums again at each new epoch
        self._epoch = 0
        self._shift = 0
        # an open stream's tail (hold_back()): sent only to keep the board from running dry
        self._hold_from: int | None = None
        self._hold_floor = 0
        # the speeds of what was sent, for a stop along the path (streaming thread, under the lock)
        self._path_speeds = PathSpeeds(segments.axis_count)
        self._thread = threading.Thread(target=self._run, name="quadstep-motion", daemon=True)

    # --- progress ------------------------------------------------------------------

    @property
    def sent(self) -> int:
        return self._sent

    @property
    def done(self) -> int:
        """Segments of this motion the board has completed."""
        return min(self._sent, self.link.segments_done - self._base_done)

    @property
    def end(self) -> MotionEnd | None:
        return self._end

    # --- control -------------------------------------------------------------------

    def start(self) -> Motion:
        self._base_done = self.link.segments_done
        self._generation = self.link.generation
        self._input_holds = self.link.holds_by_input
        self._starvations = self.link.stats.starvations
        self._thread.start()
        return self

    @property
    def started(self) -> bool:
        return self._thread.ident is not None

    def wait(self, timeout: float | None = None) -> MotionEnd | None:
        self._ended.wait(timeout)
        return self._end

    def cut(self, index: int) -> bool:
        """Stop streaming before segment `index` instead of at `last`, for a plan made again from
        there (a feed override, lines added) to go on in its place without a stop (go_on()); False
        when that segment is sent already or is not before `last`. Until go_on() the motion waits
        at `index` while the board runs what it has."""
        with self._lock:
            if (
                self._halting
                or self._end is not None
                or not self.first + self._sent <= index < self.last
            ):
                return False
            # what goes on from `index` is the new plan's: the segments before it, none kept back
            self.last, self._cut, self._hold_from = index, True, None
            return True

    def go_on(
        self,
        segments: Segments,
        shift: int,
        last: int,
        outputs: Sequence[tuple[int, Outputs]],
        hold_from: int | None = None,
        floor_ticks: int = 0,
    ) -> bool:
        """After cut(): stream `segments` (a plan made again from the cut, the same as this one's
        before it) up to `last`, this motion's segment i being their i − `shift` (a plan that let
        go of what ran), with `outputs` (from the cut on) and its tail from `hold_from` kept back as
        hold_back() keeps it; at once, whether or not the motion has reached the cut. False when
        the motion was not cut or has ended (or is halting)."""
        with self._lock:
            if self._halting or self._end is not None or not self._cut:
                return False
            # the outputs before the cut are this plan's still; from it on, the new plan's
            kept = [(at - shift, message) for at, message in self._outputs if at < self.last]
            self._outputs = deque(kept + sorted(outputs, key=lambda o: o[0]))
            self.segments, self.first, self.last = segments, self.first - shift, last
            self._shift += shift
            self._cut, self._hold_from, self._hold_floor = False, hold_from, floor_ticks
            self._epoch += 1
        self._space.set()
        return True

    @property
    def held_from(self) -> int | None:
        """The first segment of the tail kept back (hold_back()), if one is."""
        return self._hold_from

    def hold_back(self, index: int | None, floor_ticks: int = 0) -> None:
        """Send segment `index` and those after it only while the board holds less than
        `floor_ticks` of motion before them (None: send everything): the end of a plan that may yet
        go on (a sender's stream), kept back so that lines arriving meanwhile can replace it."""
        with self._lock:
            self._hold_from, self._hold_floor = index, floor_ticks
        self._space.set()

    def halt(self, reason: str = "stop") -> MotionEnd:
        """Bring the machine to rest now (HOLD) and end the motion; idempotent."""
        stop_ns = time.monotonic_ns()  # the stop event, for latency figures
        with self._lock:
            first = self._end is None and self._halting is None
            if first:
                self._halting = reason
        if not first:
            self._ended.wait()
            assert self._end is not None
            return self._end
        self._space.set()
        done = self.done
        try:
            rest = bring_to_rest(self.link, self.decels, self._along_path(done))
        except AlarmError as exc:  # the board had halted on an alarm already
            end = self._after_alarm(exc)
            end = MotionEnd(reason, end.position, done, stop_ns, error=end.error)
        except LinkError as exc:
            end = MotionEnd("error", (), done, stop_ns, error=f"could not stop the motion: {exc}")
        else:
            end = MotionEnd(
                reason,
                self._axes(rest.position),
                done,
                stop_ns,
                rest.held,
                rest.hold_tick,
                hold_decels=rest.decels,
            )
        self._finish(end, from_halt=True)
        return end

    def _along_path(self, done: int) -> AlongPath | None:
        """The stop along the path (along_path.py) for a HOLD now, with `done` segments of this
        motion run."""
        if not supports_hold(self.link):
            return None
        with self._lock:
            segments, first, sent = self.segments, self.first, self._sent
        decels = firmware_decels(self.link, self.decels)
        speeds = self._path_speeds.reader(segments, first)
        return along_path(speeds, first + done, first + sent, self._base_done + done, decels)

    # --- the streaming thread --------------------------------------------------------

    def _run(self) -> None:
        unregister = self.link.on_report(self._on_report)
        try:
            self._stream()
            status = self.link.wait_idle(generation=self._generation)
            self._finish(MotionEnd("done", self._axes(status.position), self.done))
        except Stopped:
            self._after_stop()  # halt(), or a STOP from elsewhere
        except AlarmError as exc:
            self._finish(self._after_alarm(exc))
        except LinkError as exc:
            self._finish(MotionEnd("error", (), self.done, error=str(exc)))
        except (
            Exception
        ) as exc:  # a fault of this program: end the motion (the board stops at its queue's end)
            self._finish(MotionEnd("error", (), self.done, error=f"streaming failed: {exc!r}"))
            raise
        finally:
            unregister()

    def _stream(self) -> None:
        identity = self.link.identity
        assert identity is not None
        size = RunSize(board_run_limit(identity), self.link, identity.tick_hz)
        chain = RunChain(self.segments.axis_count)
        choice = frame_choice(identity)  # the frame kinds this board takes fastest
        epoch, index, ticks = -1, self.first, [0]
        while True:
            with self._lock:
                renumbered = self._epoch != epoch  # the start, or go_on()
                if renumbered:
                    index -= self._shift
                    self._shift, epoch = 0, self._epoch
                segments, first, last, cut = self.segments, self.first, self.last, self._cut
                output = self._outputs[0][0] if self._outputs else None
            if renumbered:  # outside the lock: a halt never waits for them
                ticks = running_sums(segments, first, last, index, ticks)
            if self._halting:
                return
            if index >= last:
                if not cut:
                    break
                self._wait_at_cut()
                continue
            k = index - first
            limit = self._sendable(index, first, ticks)
            if limit <= index:
                continue  # the tail kept back: waited for the board to run some, a cut or a release
            batch = self._batch(size, k, ticks, identity.queue_capacity)
            end = self._frame_end(index, first, min(limit, last), batch, ticks)
            if output is not None and output > index:
                end = min(end, output)  # an output goes out before its segment, between frames
            before = chain.copy()
            message = next_frame(
                segments, index, end, chain, batch, choice.cubic_runs, choice.quadratic_runs
            )
            count = queue_slots(message)
            self._wait_for_room(segments, first, k, k + count - 1, ticks, identity)
            # Checked and sent under the lock: once halt() has set _halting nothing more is
            # sent, so no segment can follow its HOLD. The room waited for above makes this
            # send return at once, so halt() never waits long for the lock.
            with self._lock:
                if self._halting:
                    return
                if self._epoch != epoch or index + count > self.last:
                    chain = before  # renumbered by go_on(), or cut() inside this frame: again
                    continue
                self._send_outputs(index)  # in stream order, before the segment
                # a restart ends this motion
                self.link.send(message, generation=self._generation, ahead=AHEAD_SLOTS)
                self._sent = k + count
                self._path_speeds.sent(k, sent_items(segments, index, count, message), self.done)
            index += count
        with self._lock:
            if not self._halting:
                self._send_outputs(None)  # those after the last segment

    def _send_outputs(self, index: int | None) -> None:
        """The OUTPUTS due before segment `index` (None: all that are left); under the lock."""
        while self._outputs and (index is None or self._outputs[0][0] <= index):
            self.link.send(
                self._outputs.popleft()[1], generation=self._generation, ahead=AHEAD_SLOTS
            )

    def _batch(self, size: RunSize, k: int, ticks: list[int], capacity: int) -> int:
        """Segments the frame that begins at segment `k` may hold: the run size; behind, no more
        than the board holds before it (it prepares them while those run) and has room for now
        (the frame waits for none)."""
        batch = size.next()
        if self._queued_ticks(k, ticks) < size.floor:
            queued = k - self.done
            batch = min(batch, max(1, queued), max(1, capacity - queued))
        return max(1, batch)

    def _frame_end(self, index: int, first: int, last: int, batch: int, ticks: list[int]) -> int:
        """The end of the frame that begins at `index`: `batch` segments, before `last`, and at
        most half the lookahead, so that the board keeps the other half queued."""
        k, end = index - first, min(last, index + batch)
        lookahead = self.lookahead_ticks
        while lookahead and end - index > 1 and ticks[end - first] - ticks[k] > lookahead // 2:
            end -= 1
        return end

    def _wait_at_cut(self) -> None:
        """Streaming has reached the cut: a short wait for go_on() or a halt. A board that runs dry
        meanwhile ends the motion (Stopped)."""
        self._space.wait(SPACE_WAIT)
        self._space.clear()
        self.link.check(self._generation)

    def _sendable(self, index: int, first: int, ticks: list[int]) -> int:
        """The segments from `index` that may be sent now end before the one returned: `last`, or
        the held-back tail's beginning (hold_back()); `index` itself when none may (after a short
        wait for the board to run some of its queue)."""
        with self._lock:
            hold_from, floor, last = self._hold_from, self._hold_floor, self.last
        if hold_from is None or hold_from >= last:
            return last
        if index < hold_from:
            return hold_from
        k, identity = index - first, self.link.identity
        half = identity.queue_capacity // 2 if identity is not None else 1
        if self._halting:
            return index + 1
        if self._queued_ticks(k, ticks) < floor and k - self.done < max(1, half):
            # the board would run dry first: as much again as the floor
            upto = bisect_left(ticks, ticks[max(0, min(self.done, k))] + floor) + first
            return min(last, max(index + 1, upto))
        self._space.wait(SPACE_WAIT)
        self._space.clear()
        self.link.check(self._generation)
        return index

    def _queued_ticks(self, k: int, ticks: list[int]) -> int:
        """Ticks of motion sent and not yet finished (the running segment's whole), before segment
        k."""
        return ticks[k] - ticks[max(0, min(self.done, k))]

    def _wait_for_room(
        self, segments: Segments, first: int, j: int, k: int, ticks: list[int], board: IdentifyReply
    ) -> None:
        """Until a frame's segments `j` … `k` (counted from `first` of `segments`) fit in the
        queue (or wait beyond it in the link's window: fits_queue) and within the lookahead, or
        the board holds fewer than MIN_QUEUED_SEGMENTS before them (a segment longer than the
        lookahead is running), or a halt."""
        last_done, since = -1, time.monotonic()
        while not self._halting:
            if self.link.generation != self._generation:
                raise Stopped("the stream was restarted (STOP) while this motion waited for room")
            # an alarm, a reset or a silent board: no room will come
            self.link.check(self._generation)
            done = self.done
            queued = k - done
            if (
                fits_queue(queued, ticks[k + 1] - ticks[max(0, done)], board)
                and ring_fits(segments, first + done, first + k, board.raster_ring)
                and (
                    self.lookahead_ticks is None
                    or j - done < MIN_QUEUED_SEGMENTS
                    or ticks[k] - ticks[max(0, done)] < self.lookahead_ticks
                )
            ):
                return
            now = time.monotonic()
            if done != last_done:
                last_done, since = done, now
            elif now - since > STALL_POLL:
                # a SPACE ack lost: the status carries the count
                alarm = status_alarm(self.link.status())
                if alarm is not None:  # the alarm flushed the queue: no room will come
                    raise alarm
                since = now
            self._space.wait(SPACE_WAIT)
            self._space.clear()

    def _after_stop(self) -> None:
        """A STOP from elsewhere (not halt()) dropped the rest of the motion: end where the board
        stands. The board's feed hold button (a hold the firmware began itself) ends it as a feed
        hold, once at rest."""
        with self._lock:
            if self._halting is not None:
                return
        try:
            if self.link.stats.starvations != self._starvations:
                self._after_starvation()
                return
            holding = [
                c.cause
                for c in self.link.input_changes
                if c.cause in (InputCause.FEED_HOLD, InputCause.TRIGGER)
            ]
            if (
                self.link.holds_by_input != self._input_holds
                and holding
                and holding[-1] == InputCause.FEED_HOLD
            ):
                status = wait_rest(self.link)
                done = self.link.last_report(HoldDone)
                self._finish(
                    MotionEnd(
                        "feed hold",
                        self._axes(status.position),
                        self.done,
                        held=True,
                        hold_tick=done.hold_tick if done is not None else None,
                    )
                )
                return
            position = self._axes(self.link.status().position)
        except LinkError as exc:
            self._finish(MotionEnd("error", (), self.done, error=str(exc)))
            return
        self._finish(MotionEnd("reset", position, self.done))

    def _after_starvation(self) -> None:
        """The queue ran dry while moving: the board stopped under control and refuses segments
        until a HOLD. The HOLD takes it to IDLE and repeats the stop's HOLD_DONE: its hold_tick and
        exact rest position."""
        rest = bring_to_rest(self.link, self.decels)
        self._finish(
            MotionEnd(
                STARVED, self._axes(rest.position), self.done, held=True, hold_tick=rest.hold_tick
            )
        )

    def _after_alarm(self, exc: AlarmError) -> MotionEnd:
        """The board halted on an alarm (positions exact); clear it so the machine can go on."""
        message = str(exc)
        try:
            status = self.link.stop()
        except LinkError as stop_exc:
            return MotionEnd(
                "error", self._axes(exc.alarm.position), self.done, error=f"{message}; {stop_exc}"
            )
        return MotionEnd("error", self._axes(status.position), self.done, error=message)

    def _axes(self, position: Sequence[int]) -> tuple[int, ...]:
        """The board reports every axis it has; the motion concerns the plan's."""
        return tuple(position[: self.segments.axis_count])

    def _on_report(self, report: Report) -> None:
        if getattr(report, "reason", None) == AckReason.SPACE:
            self._space.set()

    def _finish(self, end: MotionEnd, from_halt: bool = False) -> None:
        with self._lock:
            if self._end is not None or (self._halting is not None and not from_halt):
                return
            self._end = end
        if self.settle is not None:
            end = self._end = self.settle(end)
        if self.on_end is not None:
            self.on_end(end)
        self._ended.set()
