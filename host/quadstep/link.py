"""The serial link to a quadstep board (PROTOCOL.md §3–4), on pyserial.

A Link owns two threads: a reader that decodes every report as it arrives,
and a writer that does all transmission (new frames within the flow-control
window, go-back-N resends on GAP and on the retransmission timeout, immediate
requests). Public methods block and are safe to call from any thread; from
asyncio or Textual call them through worker threads (asyncio.to_thread).
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import serial

from .protocol import (
    Ack,
    AckReason,
    Alarm,
    DecodeError,
    Decoder,
    ErrorCode,
    ErrorReport,
    Event,
    Frame,
    Hold,
    HoldDone,
    Identify,
    IdentifyReply,
    MessageType,
    Report,
    Request,
    Segment,
    State,
    Status,
    StatusReport,
    Stop,
    encode,
    message_type,
)
from .protocol.constants import DECEL_MAX, MAX_AXES, MAX_IN_FLIGHT, PROTOCOL_VERSION

if TYPE_CHECKING:
    from .emulator import Emulator

DEFAULT_BAUD = 500_000
_SEQUENCED_TYPES = frozenset(t for t in MessageType if t.is_sequenced)
# What pyserial raises once the port is gone (TypeError and AttributeError from a port closed under it).
_PORT_FAILURES = (serial.SerialException, OSError, TypeError, AttributeError)


class LinkError(Exception):
    """The link cannot go on: port closed, firmware unanswering, wrong version."""


class LinkTimeout(LinkError):
    """The firmware did not answer after every retry."""


class ProtocolVersionError(LinkError):
    """The firmware speaks a protocol version this host does not know."""


class Stopped(LinkError):
    """stop() or hold() was called while this call was waiting; what it was sending was dropped."""


class FirmwareError(LinkError):
    """The firmware refused a frame with an ERROR report."""

    def __init__(self, report: ErrorReport) -> None:
        self.report = report
        super().__init__(f"firmware refused a frame: {report.describe()}")

    @property
    def code(self) -> str:
        return self.report.code.name

    @property
    def field(self) -> str | None:
        return self.report.field.name if self.report.field is not None else None

    @property
    def axis(self) -> int | None:
        return self.report.axis


class AlarmError(LinkError):
    """The firmware raised an alarm: motion halted, the queue was flushed."""

    def __init__(self, alarm: Alarm) -> None:
        self.alarm = alarm
        super().__init__(
            f"firmware alarm {alarm.code.name} at motion tick {alarm.motion_ticks}, "
            f"positions {list(alarm.position)}; stop() clears it"
        )


@dataclass
class LinkStats:
    """Counters of everything the link did; `retransmits` counts frames written again."""

    frames_sent: int = 0
    bytes_sent: int = 0
    frames_received: int = 0
    bytes_received: int = 0
    retransmits: int = 0
    gaps: int = 0
    duplicates: int = 0
    queue_full: int = 0
    timeouts: int = 0
    errors: int = 0
    alarms: int = 0
    decode_errors: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)


@dataclass
class _Outgoing:
    seq: int
    data: bytes
    is_segment: bool
    transmissions: int = 0


@dataclass
class _Waiter:
    """An immediate request waiting for the report that answers it."""

    seq: int
    request_type: MessageType
    reply_type: MessageType
    reply: Report | None = None
    error: ErrorReport | None = None


@dataclass
class _State:
    """Everything the two threads and the callers share; guarded by Link._cond."""

    base: int = 0  # firmware's next_seq as last reported: the seq of frames[0]
    free: int = 0
    frames: list[_Outgoing] = field(default_factory=list)
    sent: int = 0  # frames[:sent] transmitted in the current go-back-N round
    last_progress: float = 0.0
    gap_handled_for: int | None = None
    urgent: deque[bytes] = field(default_factory=deque)
    waiter: _Waiter | None = None
    request_seq: int = 0x40
    failure: LinkError | None = None
    stopping: bool = False
    generation: int = 0
    done16: int = 0
    done_total: int = 0
    expected_done: int = 0
    last_rx: float = 0.0
    last_poll: float = 0.0
    last_alarm: Alarm | None = None
    hold_done: HoldDone | None = None  # the latest HOLD_DONE
    holds_done: int = 0  # HOLD_DONE events received
    closed: bool = False


ReportCallback = Callable[[Report], None]


class Link:
    """A connected session with the firmware. Build it with Link.open(url)."""

    def __init__(
        self,
        port: serial.SerialBase,
        *,
        rto: float = 0.25,
        retries: int = 8,
        request_timeout: float = 0.5,
        poll_interval: float = 1.0,
    ) -> None:
        self._port = port
        self.rto = rto
        self.retries = retries
        self.request_timeout = request_timeout
        self.poll_interval = poll_interval
        self.stats = LinkStats()
        self.identity: IdentifyReply | None = None
        self.emulator: Emulator | None = None  # the emulator process behind this link, if any
        self._cond = threading.Condition()
        self._request_lock = threading.Lock()
        self._s = _State()
        self._callbacks: list[ReportCallback] = []
        self._decoder = Decoder("to_host")
        self._reader = threading.Thread(target=self._read_loop, name="quadstep-link-reader", daemon=True)
        self._writer = threading.Thread(target=self._write_loop, name="quadstep-link-writer", daemon=True)
        self._reader.start()
        self._writer.start()

    # --- opening and closing ---------------------------------------------------

    @classmethod
    def open(
        cls,
        url: str,
        baudrate: int = DEFAULT_BAUD,
        *,
        rto: float = 0.25,
        retries: int = 8,
        request_timeout: float = 0.5,
        connect: bool = True,
    ) -> Link:
        """Open `url` (a device such as /dev/ttyACM0 or /dev/pts/N, or socket://host:port) and connect."""
        try:
            port = serial.serial_for_url(url, baudrate=baudrate, timeout=0.05, write_timeout=10)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkError(f"cannot open {url}: {exc}") from exc
        link = cls(port, rto=rto, retries=retries, request_timeout=request_timeout)
        if connect:
            try:
                link.connect()
            except BaseException:
                link.close()
                raise
        return link

    def connect(self) -> IdentifyReply:
        """Identify the firmware, check its protocol version and adopt its sequence state."""
        with self._cond:
            self._s.urgent.append(b"\x00")  # ends any partial frame left on the line
            self._cond.notify_all()
        ident = self._request(Identify(), MessageType.IDENTIFY_REPLY)
        assert isinstance(ident, IdentifyReply)
        if ident.protocol_version != PROTOCOL_VERSION:
            raise ProtocolVersionError(
                f"firmware speaks protocol version {ident.protocol_version}; "
                f"this host speaks version {PROTOCOL_VERSION}"
            )
        self.identity = ident
        status = self.status()
        with self._cond:
            self._resync(status)
        return ident

    def close(self) -> None:
        with self._cond:
            self._s.closed = True
            self._cond.notify_all()
        for thread in (self._writer, self._reader):
            if thread.is_alive() and thread is not threading.current_thread():
                thread.join(timeout=2)
        self._port.close()

    def __enter__(self) -> Link:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- properties --------------------------------------------------------------

    @property
    def segments_done(self) -> int:
        """Segments the firmware has completed since reset (unwrapped from ACK `done`)."""
        with self._cond:
            return self._s.done_total

    @property
    def last_alarm(self) -> Alarm | None:
        with self._cond:
            return self._s.last_alarm

    @property
    def in_flight(self) -> int:
        """Sequenced frames not yet acknowledged."""
        with self._cond:
            return len(self._s.frames)

    @property
    def axis_count(self) -> int:
        return self._identity().axis_count

    @property
    def tick_hz(self) -> int:
        return self._identity().tick_hz

    @property
    def last_hold_done(self) -> HoldDone | None:
        """The latest EVENT HOLD_DONE received."""
        with self._cond:
            return self._s.hold_done

    def on_report(self, callback: ReportCallback) -> Callable[[], None]:
        """Call `callback(report)` for every ALARM, ERROR, EVENT and SPACE ack; returns an unregister function.

        Callbacks run in the reader thread: they must return quickly and not call the Link.
        """
        with self._cond:
            self._callbacks.append(callback)

        def unregister() -> None:
            with self._cond:
                if callback in self._callbacks:
                    self._callbacks.remove(callback)

        return unregister

    # --- immediate requests ------------------------------------------------------

    def identify(self) -> IdentifyReply:
        reply = self._request(Identify(), MessageType.IDENTIFY_REPLY)
        assert isinstance(reply, IdentifyReply)
        return reply

    def status(self) -> StatusReport:
        reply = self._request(Status(), MessageType.STATUS_REPORT)
        assert isinstance(reply, StatusReport)
        return reply

    def stop(self) -> StatusReport:
        """Stop at once: drop every unacknowledged frame, flush the firmware's queue, clear any alarm."""
        with self._request_lock:
            return self._restart_stream(Stop())

    def _restart_stream(self, message: Stop | Hold) -> StatusReport:
        """Drop every unsent and unacknowledged frame and send `message` (STOP or HOLD), which makes its
        seq the firmware's next_seq; resynchronise from the answer. Call with _request_lock held."""
        with self._cond:
            s = self._s
            s.generation += 1
            seq = (s.base + len(s.frames)) & 0xFF
            s.base = seq
            s.frames.clear()
            s.sent = 0
            s.stopping = True
            self._cond.notify_all()
        try:
            reply = self._request_locked(message, MessageType.STATUS_REPORT, seq)
        except LinkError:
            with self._cond:
                self._s.stopping = False
            raise
        assert isinstance(reply, StatusReport)
        with self._cond:
            self._resync(reply)
            self._s.stopping = False
            self._s.failure = None
            self._cond.notify_all()
        return reply

    # --- hold ---------------------------------------------------------------------

    def hold_message(self, decels: Sequence[int]) -> Hold:
        """The HOLD for `decels` (one per firmware axis, or one for all), checked against the firmware's axes."""
        count = self.axis_count
        values = list(decels)
        if len(values) == 1:
            values *= count
        if len(values) != count:
            raise ValueError(f"hold needs 1 or {count} decelerations (one per axis), got {len(values)}")
        for axis, d in enumerate(values):
            if not isinstance(d, int) or not 1 <= d <= DECEL_MAX:
                raise ValueError(f"hold deceleration of axis {axis} is {d!r}; limit 1..{DECEL_MAX} "
                                 "(in 1/2^24 step per tick²)")
        return Hold(decel=tuple(values + [0] * (MAX_AXES - count)))  # type: ignore[arg-type]

    def hold(self, decels: Sequence[int], timeout: float | None = None) -> HoldDone:
        """Decelerate every moving axis to rest and discard the queue; returns the HOLD_DONE Event.

        `decels`: per axis (or one for all) in 1/2^24 step per tick², 1..8191 (at 50 kHz one unit is
        about 149 steps/s²). Like stop(), drops every unsent and unacknowledged frame (a thread
        waiting in send() raises Stopped). The Event gives `hold_tick` (the motion tick at which the
        deceleration began), `motion_ticks` (when the last axis stopped) and the rest positions;
        engine_model.predict_hold reproduces every step in between. Raises AlarmError if the firmware
        is or goes into ALARM instead (for a hold that found the queue run dry while moving),
        LinkTimeout after `timeout` seconds.
        """
        message = self.hold_message(decels)
        with self._cond:
            seen = self._s.holds_done
        with self._request_lock:
            try:
                self._restart_stream(message)
            except FirmwareError as exc:
                if exc.report.code == ErrorCode.ALARM_ACTIVE:
                    raise self._alarm_error() from exc
                raise
            with self._cond:
                generation = self._s.generation
        done = self._wait_hold_done(message, seen, generation, timeout)
        status = self.status()  # the queue is empty now: adopt its free slots and counts
        with self._cond:
            if self._s.generation == generation and not self._s.frames:
                self._resync(status)
        return done

    def hold_async(self, decels: Sequence[int], timeout: float | None = None) -> Future[HoldDone]:
        """hold() in a thread of its own: returns at once with a Future of the HOLD_DONE Event."""
        message = self.hold_message(decels)  # bad input is refused here, not in the thread
        future: Future[HoldDone] = Future()

        def run() -> None:
            try:
                future.set_result(self.hold(message.decel[: self.axis_count], timeout))
            except BaseException as exc:  # handed to whoever waits on the future
                future.set_exception(exc)

        threading.Thread(target=run, name="quadstep-hold", daemon=True).start()
        return future

    def _alarm_error(self) -> LinkError:
        alarm = self.last_alarm
        return AlarmError(alarm) if alarm is not None else LinkError("firmware is in ALARM; stop() clears it")

    def _wait_hold_done(self, message: Hold, seen: int, generation: int, timeout: float | None) -> HoldDone:
        """Until a HOLD_DONE newer than `seen` arrives. A hold may take long, so the firmware is asked how it
        is going every poll_interval; once it is no longer holding, a HOLD_DONE lost on the wire is asked
        for again by repeating the HOLD (at rest the firmware repeats the report)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            with self._cond:
                wait = self.poll_interval if deadline is None else min(self.poll_interval, deadline - time.monotonic())
                self._cond.wait_for(
                    lambda: self._s.holds_done > seen or self._s.failure is not None
                    or self._s.generation != generation or self._s.closed,
                    timeout=max(0.0, wait),
                )
                if self._s.holds_done > seen:
                    done = self._s.hold_done
                    assert done is not None
                    return done
                self._raise_failure(generation)
            if deadline is not None and time.monotonic() >= deadline:
                raise LinkTimeout(f"no HOLD_DONE within {timeout:g} s (the firmware may still be decelerating)")
            status = self.status()
            if status.state == State.ALARM:
                raise self._alarm_error()
            if status.state != State.HOLDING:
                with self._cond:
                    if self._s.holds_done > seen or self._s.generation != generation:
                        continue
                with self._request_lock:
                    self._request_locked(message, MessageType.STATUS_REPORT, status.next_seq)

    def _request(self, message: Request, reply_type: MessageType) -> Report:
        with self._request_lock:
            with self._cond:
                seq = self._next_request_seq()
            return self._request_locked(message, reply_type, seq)

    def _request_locked(self, message: Request, reply_type: MessageType, seq: int) -> Report:
        name = message_type(message).name
        data = encode(message, seq)
        waiter = _Waiter(seq, message_type(message), reply_type)
        with self._cond:
            self._s.waiter = waiter
            try:
                for _ in range(self.retries):
                    self._raise_if_closed()
                    self._s.urgent.append(data)
                    self._cond.notify_all()
                    answered = self._cond.wait_for(
                        lambda: waiter.reply is not None or waiter.error is not None or self._s.closed,
                        timeout=self.request_timeout,
                    )
                    if waiter.error is not None:
                        raise FirmwareError(waiter.error)
                    if answered and waiter.reply is not None:
                        return waiter.reply
                    self.stats.timeouts += 1
                self._raise_if_closed()
                raise LinkTimeout(
                    f"no answer to {name} after {self.retries} tries of {self.request_timeout:g} s "
                    f"(is the board connected, running quadstep firmware, at this baud rate?)"
                )
            finally:
                self._s.waiter = None

    # --- sequenced messages ------------------------------------------------------

    def send(self, message: Segment | Request, timeout: float | None = None) -> int:
        """Queue a sequenced message (Segment, SetPosition); blocks while the window is full.

        Returns the seq it was given. Raises the first failure seen since the last
        stop(): FirmwareError, AlarmError, LinkTimeout; Stopped if stop() is called meanwhile.
        """
        mtype = message_type(message)
        if not mtype.is_sequenced:
            raise ValueError(f"{mtype.name} is not a sequenced message; use its own method")
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            s = self._s
            generation = s.generation
            while True:
                self._raise_failure(generation)
                if len(s.frames) < min(s.free, MAX_IN_FLIGHT):
                    break
                if not self._wait(deadline):
                    raise LinkTimeout(f"flow-control window still full after {timeout:g} s")
            seq = (s.base + len(s.frames)) & 0xFF
            s.frames.append(_Outgoing(seq, encode(message, seq), mtype == MessageType.SEGMENT))
            self._cond.notify_all()
            return seq

    def drain(self, timeout: float | None = None) -> None:
        """Wait until the firmware has acknowledged every frame sent."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            generation = self._s.generation
            while True:
                self._raise_failure(generation)
                if not self._s.frames:
                    return
                if not self._wait(deadline):
                    raise LinkTimeout(f"{len(self._s.frames)} frames still unacknowledged after {timeout:g} s")

    def wait_idle(self, timeout: float | None = None) -> StatusReport:
        """Wait until every frame is acknowledged and the firmware is IDLE; returns its final status."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            generation = self._s.generation
        self.drain(timeout)
        while True:
            with self._cond:
                remaining = self.poll_interval if deadline is None else max(0.0, deadline - time.monotonic())
                self._cond.wait_for(
                    lambda: self._s.done_total >= self._s.expected_done
                    or self._s.failure is not None
                    or self._s.generation != generation,
                    timeout=min(self.poll_interval, remaining),
                )
                self._raise_failure(generation)
            status = self.status()
            with self._cond:
                self._raise_failure(generation)
            if status.state == State.ALARM:
                alarm = self.last_alarm
                if alarm is None:
                    raise LinkError(f"firmware is in ALARM {status.alarm.name if status.alarm else ''}")
                raise AlarmError(alarm)
            if status.state == State.IDLE and status.queue_fill == 0:
                return status
            time.sleep(0.005)  # the last segment is still running
            if deadline is not None and time.monotonic() >= deadline:
                raise LinkTimeout(
                    f"firmware still {status.state.name} with {status.queue_fill} segments queued after {timeout:g} s"
                )

    # --- shared-state helpers (call with self._cond held) ------------------------

    def _identity(self) -> IdentifyReply:
        if self.identity is None:
            raise LinkError("not connected: call connect() first")
        return self.identity

    def _next_request_seq(self) -> int:
        self._s.request_seq = (self._s.request_seq + 1) & 0xFF
        return self._s.request_seq

    def _wait(self, deadline: float | None) -> bool:
        if deadline is None:
            self._cond.wait()
            return True
        remaining = deadline - time.monotonic()
        return remaining > 0 and (self._cond.wait(remaining) or time.monotonic() < deadline)

    def _raise_if_closed(self) -> None:
        if self._s.closed:
            raise self._s.failure or LinkError("link closed")

    def _raise_failure(self, generation: int) -> None:
        self._raise_if_closed()
        if self._s.failure is not None:
            raise self._s.failure
        if generation != self._s.generation:
            raise Stopped("stop() or hold() was called: unsent and unacknowledged frames were dropped")

    def _resync(self, status: StatusReport) -> None:
        s = self._s
        s.base = status.next_seq
        s.free = self._identity().queue_capacity - status.queue_fill
        s.done_total = status.segments_done
        s.done16 = status.segments_done & 0xFFFF
        s.expected_done = status.segments_done + status.queue_fill
        s.gap_handled_for = None

    def _fail(self, failure: LinkError) -> None:
        if self._s.failure is None:
            self._s.failure = failure

    # --- reader thread ----------------------------------------------------------------

    def _read_loop(self) -> None:
        while True:
            with self._cond:
                if self._s.closed:
                    return
            try:
                data = self._port.read(self._port.in_waiting or 1)
            except _PORT_FAILURES as exc:
                self._port_failed(exc)
                return
            if not data:
                continue
            notify: list[Report] = []
            with self._cond:
                self.stats.bytes_received += len(data)
                self._s.last_rx = time.monotonic()
                for item in self._decoder.feed(data):
                    if isinstance(item, DecodeError):
                        self.stats.decode_errors += 1
                    else:
                        self.stats.frames_received += 1
                        if self._on_frame(item):
                            notify.append(item.message)  # type: ignore[arg-type]
                self._cond.notify_all()
                callbacks = list(self._callbacks) if notify else []
            for report in notify:
                for callback in callbacks:
                    callback(report)

    def _port_failed(self, exc: Exception) -> None:
        """The port raised in the reader or the writer thread: the link is closed."""
        with self._cond:
            if not self._s.closed:
                self._fail(LinkError(f"serial port failed: {exc}"))
                self._s.closed = True
            self._cond.notify_all()

    def _on_frame(self, frame: Frame) -> bool:
        """Apply one report to the shared state; True if on_report callbacks want it."""
        m = frame.message
        if isinstance(m, Ack):
            self._on_ack(m)
            return m.reason == AckReason.SPACE
        if isinstance(m, ErrorReport):
            self._on_error(m)
            return True
        if isinstance(m, Alarm):
            self.stats.alarms += 1
            self._s.last_alarm = m
            if not self._s.stopping:
                self._fail(AlarmError(m))
            return True
        if isinstance(m, Event):
            if isinstance(m, HoldDone):
                self._s.hold_done = m
                self._s.holds_done += 1
            return True
        waiter = self._s.waiter
        if waiter is not None and frame.seq == waiter.seq and message_type(m) == waiter.reply_type:
            waiter.reply = m  # type: ignore[assignment]
        if isinstance(m, StatusReport):
            self._on_status(m)
        return False

    def _on_ack(self, ack: Ack) -> None:
        s = self._s
        s.done_total += (ack.done - s.done16) & 0xFFFF
        s.done16 = ack.done
        if ack.reason == AckReason.GAP:
            self.stats.gaps += 1
        elif ack.reason == AckReason.DUPLICATE:
            self.stats.duplicates += 1
        elif ack.reason == AckReason.QUEUE_FULL:
            self.stats.queue_full += 1
        if s.stopping:
            return
        advance = (ack.next_seq - s.base) & 0xFF
        if advance > len(s.frames):
            return  # about frames from before a stop or resync
        consumed = s.frames[:advance]
        del s.frames[:advance]
        s.sent = max(0, s.sent - advance)
        s.base = ack.next_seq
        s.free = ack.free
        accepted_last = ack.reason == AckReason.ACCEPTED
        for i, frame in enumerate(consumed):
            # A frame acknowledged only by a later ACK (its own was lost) was accepted unless an ERROR said so.
            if frame.is_segment and (accepted_last or i < len(consumed) - 1):
                s.expected_done += 1
        if advance:
            s.last_progress = time.monotonic()
            s.gap_handled_for = None
        if ack.reason in (AckReason.GAP, AckReason.QUEUE_FULL) and s.gap_handled_for != ack.next_seq:
            s.gap_handled_for = ack.next_seq
            s.sent = 0  # go back N: resend from next_seq as the window allows

    def _on_error(self, error: ErrorReport) -> None:
        self.stats.errors += 1
        waiter = self._s.waiter
        if waiter is not None and error.frame_type == waiter.request_type and error.frame_seq == waiter.seq:
            waiter.error = error
            return
        ours = any(f.seq == error.frame_seq for f in self._s.frames)
        if ours and error.frame_type in _SEQUENCED_TYPES and not self._s.stopping:
            self._fail(FirmwareError(error))
        # Framing errors (a frame damaged on the wire) are repaired by go-back-N; errors about
        # frames this link did not send (another writer on the line) are only counted.

    def _on_status(self, status: StatusReport) -> None:
        s = self._s
        s.done_total = status.segments_done
        s.done16 = status.segments_done & 0xFFFF
        if not s.frames and not s.stopping and status.next_seq == s.base and self.identity is not None:
            s.free = self.identity.queue_capacity - status.queue_fill  # repairs a lost SPACE ack

    # --- writer thread ----------------------------------------------------------------

    def _write_loop(self) -> None:
        while True:
            with self._cond:
                chunk = self._collect_output()
                if chunk is None:
                    return
            try:
                self._port.write(chunk)
            except _PORT_FAILURES as exc:
                self._port_failed(exc)
                return

    def _collect_output(self) -> bytes | None:
        """Wait for something to write and return it; None once closed."""
        s = self._s
        while not s.closed:
            now = time.monotonic()
            if s.sent and s.failure is None and now - s.last_progress >= self.rto:
                self.stats.timeouts += 1
                s.sent = 0  # retransmission timeout: go back N
                s.gap_handled_for = None
            out = bytearray()
            while s.urgent:
                data = s.urgent.popleft()
                self.stats.frames_sent += data != b"\x00"
                out += data
            if s.failure is None and not s.stopping:
                limit = min(len(s.frames), s.free, MAX_IN_FLIGHT)
                while s.sent < limit:
                    frame = s.frames[s.sent]
                    if frame.transmissions > self.retries:
                        self._fail(LinkTimeout(
                            f"frame seq {frame.seq} unacknowledged after {self.retries} resends"
                        ))
                        self._cond.notify_all()
                        break
                    if frame.transmissions:
                        self.stats.retransmits += 1
                    frame.transmissions += 1
                    if s.sent == 0:
                        s.last_progress = now
                    out += frame.data
                    self.stats.frames_sent += 1
                    s.sent += 1
                if self._window_stalled(now):
                    s.last_poll = now
                    self.stats.frames_sent += 1
                    out += encode(Status(), self._next_request_seq())
            if out:
                self.stats.bytes_sent += len(out)
                return bytes(out)
            waits = [self.poll_interval]
            if s.sent:
                waits.append(s.last_progress + self.rto - now)
            self._cond.wait(max(0.001, min(waits)))
        return None

    def _window_stalled(self, now: float) -> bool:
        """Nothing in flight, the window closed, and no report for a while: a SPACE ack may be lost."""
        s = self._s
        return (
            self.identity is not None
            and not s.frames
            and s.free == 0
            and now - max(s.last_rx, s.last_poll) >= self.poll_interval
        )


__all__ = [
    "AlarmError", "DEFAULT_BAUD", "FirmwareError", "Link", "LinkError", "LinkStats", "LinkTimeout",
    "ProtocolVersionError", "Stopped",
]
