"""The serial link to a quadstep board (PROTOCOL.md §3–4): requests, the sequenced stream, reports.

A Link joins a Transport (the port, a reader and a writer thread), a
SendWindow (which sequenced frames to write, and when), an Inbox (what the
reader learns from each report) and an Outbox (what is written next: by the
reader where a report made it due, else by the writer), all under one
condition variable. Public methods block and are safe from any
thread (from asyncio or Textual: worker threads). HOLD is hold.py's.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TypeVar

import serial

from ..protocol import (
    Alarm,
    Identify,
    IdentifyReply,
    InputChange,
    Report,
    Request,
    State,
    Status,
    StatusReport,
    Stop,
    encode,
)
from ..protocol.constants import PROTOCOL_VERSION, is_sequenced
from ..protocol.messages import queue_slots
from .errors import (
    AlarmError,
    BoardSilent,
    LinkError,
    LinkTimeout,
    ProtocolVersionError,
    Stopped,
    known_text,
)
from .outbox import Outbox
from .port_open import open_port
from .reports import Inbox, Waiter
from .stats import LinkStats
from .transport import Transport
from .window import SendWindow

DEFAULT_BAUD = 500_000
R = TypeVar("R", bound=Report)
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
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.retries = retries
        self.request_timeout = request_timeout
        self.poll_interval = poll_interval
        self.stats = LinkStats()
        self.identity: IdentifyReply | None = None
        self._clock = clock
        lock = threading.RLock()
        self._cond = threading.Condition(lock)  # whoever waits on the link's state
        # the writer waits apart, woken when there may be something to write, not at every report
        self._writable = threading.Condition(lock)
        self._request_lock = threading.Lock()  # one immediate request at a time
        self._window = SendWindow(clock, rto, retries, self.stats)
        self._callbacks: list[ReportCallback] = []
        # these two shared with the threads, guarded by _cond
        self._in = Inbox(self._window, self.stats)
        self._out = Outbox(self._window, self._in, self.stats, poll_interval)
        self._transport = Transport(
            port,
            self._cond,
            self._writable,
            self._on_look,
            self._on_data,
            self._next_output,
            self._port_failed,
            self._output_now,
        )
        self._transport.start()

    # --- opening and closing ---------------------------------------------------------------------

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
        """Open `url` (a device such as /dev/ttyACM0 or /dev/pts/N, or socket://host:port) and
        connect."""
        try:
            port = open_port(url, baudrate)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkError(f"cannot open {url}: {exc}") from exc
        link = cls(port, rto=rto, retries=retries, request_timeout=request_timeout)
        if connect:
            try:
                link.connect()
            except BaseException as exc:
                link.close()
                raise LinkError.at_connect(link._transport.heard, exc) from None
        return link

    def connect(self) -> IdentifyReply:
        """Identify the firmware, check its protocol version and adopt its sequence state."""
        with self._cond:
            self._out.urgent.append(b"\x00")  # ends any partial frame left on the line
            self._wake()
        ident = self.identify()
        if ident.protocol_version != PROTOCOL_VERSION:
            raise ProtocolVersionError(
                f"firmware speaks protocol version {ident.protocol_version}; "
                f"this host speaks version {PROTOCOL_VERSION}"
            )
        self.identity = ident
        status = self.status()
        with self._cond:
            self._in.queue_capacity = ident.queue_capacity
            self._in.resync(status)
        return ident

    def close(self) -> None:
        self._transport.close()

    def __enter__(self) -> Link:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- properties ------------------------------------------------------------------------------

    @property
    def segments_done(self) -> int:
        """Segments the firmware has completed since reset (unwrapped from ACK `done`)."""
        with self._cond:
            return self._in.done_total

    @property
    def in_flight(self) -> int:
        """Sequenced frames not yet acknowledged."""
        with self._cond:
            return self._window.in_flight

    @property
    def generation(self) -> int:
        """How many times the stream was restarted (STOP, HOLD): a waiter that saw another gives
        up."""
        with self._cond:
            return self._in.generation

    @property
    def axis_count(self) -> int:
        return self._identity().axis_count

    @property
    def tick_hz(self) -> int:
        return self._identity().tick_hz

    @property
    def last_alarm(self) -> Alarm | None:
        return self.last_report(Alarm)

    def last_report(self, cls: type[R]) -> R | None:
        """The latest unsolicited report (ALARM, or an EVENT kind such as HoldDone) of class
        `cls`."""
        with self._cond:
            report = self._in.latest.get(cls)
        assert report is None or isinstance(report, cls)  # kept by its class
        return report

    @property
    def input_changes(self) -> list[InputChange]:
        """The latest EVENT INPUT reports (up to 256), oldest first."""
        with self._cond:
            return list(self._in.input_changes)

    @property
    def holds_by_input(self) -> int:
        """Holds the firmware began itself at an input so far (each restarted the stream)."""
        with self._cond:
            return self._in.held_by_input

    def report_count(self, cls: type[Report]) -> int:
        """How many unsolicited reports of class `cls` arrived so far."""
        with self._cond:
            return self._in.counts[cls]

    def on_report(self, callback: ReportCallback) -> Callable[[], None]:
        """Call `callback(report)` for every ALARM, ERROR, EVENT and SPACE ack; returns an
        unregister function.

        Callbacks run in the reader thread: they must return quickly and not call the Link.
        """
        with self._cond:
            self._callbacks.append(callback)

        def unregister() -> None:
            with self._cond:
                if callback in self._callbacks:
                    self._callbacks.remove(callback)

        return unregister

    # --- immediate requests ----------------------------------------------------------------------

    def identify(self) -> IdentifyReply:
        return self.request(Identify(), IdentifyReply)

    def status(self) -> StatusReport:
        return self.request(Status(), StatusReport)

    def stop(self) -> StatusReport:
        """Stop at once: drop every unacknowledged frame, flush the firmware's queue, clear any
        alarm."""
        return self.restart(Stop())[0]

    def restart(self, message: Request) -> tuple[StatusReport, int]:
        """Drop every unsent and unacknowledged frame and send `message` (STOP or HOLD), which makes
        its seq the firmware's next_seq; resynchronise from the answer. Returns it and the new
        generation."""
        with self._request_lock:
            with self._cond:
                self._in.generation += 1
                generation = self._in.generation
                seq = self._window.restart()
                self._in.stopping = True
                self._wake()
            try:
                reply = self._request_locked(message, StatusReport, seq)
            except BaseException:
                with self._cond:
                    self._in.stopping = False
                raise
            with self._cond:
                self._in.resync(reply)
                self._in.stopping = False
                self._in.failure = None
                self._wake()
            return reply, generation

    def request(self, message: Request, reply_type: type[R], seq: int | None = None) -> R:
        """Send an immediate request and wait for its answer, resending it on timeout (it is
        idempotent)."""
        with self._request_lock:
            if seq is None:
                with self._cond:
                    seq = self._out.next_request_seq()
            return self._request_locked(message, reply_type, seq)

    def _request_locked(self, message: Request, reply_type: type[R], seq: int) -> R:
        data = encode(message, seq)
        waiter = Waiter(seq, message.CODE, reply_type.CODE)
        with self._cond:
            self._in.waiter = waiter
            try:
                for _ in range(self.retries):
                    self._raise_if_closed()
                    self._out.urgent.append(data)
                    self._wake()
                    self._cond.wait_for(
                        lambda: waiter.answered or self._transport.closed,
                        timeout=self.request_timeout,
                    )
                    waiter.raise_refusal(message.NAME)
                    reply = waiter.reply
                    if reply is not None:
                        assert isinstance(reply, reply_type)  # the waiter takes only its CODE
                        return reply
                    self.stats.timeouts += 1
                self._raise_if_closed()
                raise LinkTimeout(
                    f"no answer to {message.NAME} after {self.retries} tries of "
                    f"{self.request_timeout:g} s (is the board connected, running quadstep "
                    "firmware, at this baud rate?)"
                    + known_text(self._in.last_status, self._in.last_alarm())
                )
            finally:
                self._in.waiter = None

    # --- sequenced messages -----------------------------------------------------------------------

    def send(
        self,
        message: Request,
        timeout: float | None = None,
        generation: int | None = None,
        ahead: int = 0,
    ) -> int:
        """Queue a sequenced message (Segment, SetPosition); blocks while the window is full: until
        the board has room for it, or `ahead` queue slots more (it then waits in the window, and
        the link's threads write it the moment a report frees its slots).

        Returns the seq it was given. Raises the first failure seen since the last stop():
        FirmwareError, AlarmError, LinkTimeout; Stopped if stop() is called meanwhile, or if the
        stream was restarted after `generation` (the one its motion began in: a hold the firmware
        began at an input ends that stream)."""
        if not is_sequenced(message.CODE):
            raise ValueError(f"{message.NAME} is not a sequenced message; use its own method")
        deadline = None if timeout is None else self._clock() + timeout
        with self._cond:
            generation = self._in.generation if generation is None else generation
            slots = queue_slots(message)
            while not self._window.room(slots, ahead):
                self._raise_failure(generation)
                if not self._wait(deadline):
                    raise LinkTimeout(f"flow-control window still full after {timeout:g} s")
            self._raise_failure(generation)
            seq = self._window.push(encode(message, self._window.next_seq), slots)
            self._wake()
            return seq

    def drain(self, timeout: float | None = None, generation: int | None = None) -> None:
        """Wait until the firmware has acknowledged every frame sent (`generation`: as for send)."""
        deadline = None if timeout is None else self._clock() + timeout
        with self._cond:
            generation = self._in.generation if generation is None else generation
            while True:
                self._raise_failure(generation)
                # a refusal waits for its status
                if not self._window.in_flight and self._in.refused is None:
                    return
                if not self._wait(deadline):
                    raise LinkTimeout(
                        f"{self._window.in_flight} frames still unacknowledged after {timeout:g} s"
                    )

    def wait_idle(
        self, timeout: float | None = None, generation: int | None = None
    ) -> StatusReport:
        """Until every frame is acknowledged and the firmware is IDLE (`generation`: as for send);
        its status."""
        deadline = None if timeout is None else self._clock() + timeout
        with self._cond:
            generation = self._in.generation if generation is None else generation
        self.drain(timeout, generation)
        while True:
            with self._cond:
                remaining = (
                    self.poll_interval if deadline is None else max(0.0, deadline - self._clock())
                )
                self._cond.wait_for(
                    lambda: (
                        self._in.done_total >= self._in.expected_done
                        or self._in.failure is not None
                        or self._in.generation != generation
                    ),
                    timeout=min(self.poll_interval, remaining),
                )
                self._raise_failure(generation)
            status = self.status()
            with self._cond:
                self._raise_failure(generation)
            if status.state == State.ALARM:
                alarm = self.last_alarm
                if alarm is None:
                    raise LinkError(
                        f"firmware is in ALARM {status.alarm.name if status.alarm else ''}"
                    )
                raise AlarmError(alarm)
            if status.state == State.IDLE and status.queue_fill == 0:
                return status
            time.sleep(0.005)  # the last segment is still running
            if deadline is not None and self._clock() >= deadline:
                raise LinkTimeout(
                    f"firmware still {status.state.name} with {status.queue_fill} segments queued "
                    f"after {timeout:g} s"
                )

    def check(self, generation: int) -> None:
        """Raise the link's failure (an alarm, a reset, a silent board), or Stopped after a
        restart."""
        with self._cond:
            self._raise_failure(generation)

    def wait_report(
        self, cls: type[R], after: int, generation: int, timeout: float | None
    ) -> R | None:
        """Until report number `after` + 1 of class `cls` (report_count) arrives: returns the latest
        one, or None after `timeout`. Raises the link's failure, or Stopped once the stream is
        restarted."""
        with self._cond:
            self._cond.wait_for(
                lambda: (
                    self._in.counts[cls] > after
                    or self._in.failure is not None
                    or self._in.generation != generation
                    or self._transport.closed
                ),
                timeout=timeout,
            )
            if self._in.counts[cls] > after:
                report = self._in.latest[cls]
                assert isinstance(report, cls)  # kept by its class
                return report
            self._raise_failure(generation)
            return None

    def resync(self, status: StatusReport, generation: int) -> None:
        """Adopt a status taken at rest, unless the stream was restarted or fed since."""
        with self._cond:
            if self._in.generation == generation and not self._window.in_flight:
                self._in.resync(status)

    # --- shared-state helpers (call with _cond held) ----------------------------------------------

    def _identity(self) -> IdentifyReply:
        if self.identity is None:
            raise LinkError("not connected: call connect() first")
        return self.identity

    def _wait(self, deadline: float | None) -> bool:
        if deadline is None:
            # woken by any change; the slice only bounds a missed one
            self._cond.wait(self.poll_interval)
            return True
        remaining = deadline - self._clock()
        return remaining > 0 and (self._cond.wait(remaining) or self._clock() < deadline)

    def _raise_if_closed(self) -> None:
        if self._transport.closed:
            raise self._in.failure or LinkError("link closed")

    def _raise_failure(self, generation: int) -> None:
        self._raise_if_closed()
        if self._in.failure is not None:
            raise self._in.failure
        if generation != self._in.generation:
            raise Stopped(
                "stop() or a hold was called: unsent and unacknowledged frames were dropped"
            )

    # --- reader -----------------------------------------------------------------------------------

    def _on_look(self) -> None:
        with self._cond:
            self._in.look(self._clock())

    def _on_data(self, data: bytes) -> None:
        with self._cond:
            notify = self._in.receive(data, self._clock())
            self._cond.notify_all()
            callbacks = list(self._callbacks) if notify else []
        for report in notify:
            for callback in callbacks:
                callback(report)

    def _port_failed(self, exc: Exception) -> None:
        """The port raised in the reader or the writer thread: the link is closed."""
        with self._cond:
            if not self._transport.closed:
                self._in.fail(LinkError(f"serial port failed: {exc}"))
                self._transport.closed = True
            self._wake()

    # --- writer -----------------------------------------------------------------------------------

    def _next_output(self) -> bytes | None:
        """Wait for something to write and return it; None once closed. Called with _cond held."""
        while not self._transport.closed:
            out = self._take_output()
            if out:
                return out
            self._writable.wait(self._out.wait_time(self._clock()))
        return None

    def _output_now(self) -> bytes:
        """What a report just made due, for the reader to write at once. Called with _cond held."""
        return self._take_output() if self._out.writable() else b""

    def _take_output(self) -> bytes:
        """What is to be written now (b"" for nothing). Called with _cond held."""
        out = self._out.take(self._clock())
        # a frame resent too often, or the board silent: wake whoever waits
        if self._in.failure is not None:
            # a silent board ends the link
            self._transport.closed |= isinstance(self._in.failure, BoardSilent)
            self._cond.notify_all()
        return out

    def _wake(self) -> None:
        """Wake whoever waits on the link, the writer too. Called with _cond held."""
        self._cond.notify_all()
        self._writable.notify()
