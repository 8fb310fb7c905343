"""What the reader thread learns from each report: the window's ACKs, how many segments are done,
the latest unsolicited report of each kind, the answer a waiting request wants, and the first
failure.

An Inbox is shared state: every method and field is used with the link's condition held.
"""

from __future__ import annotations

from collections import defaultdict, deque
from dataclasses import dataclass

from ..protocol import (
    Ack,
    AckReason,
    Alarm,
    DecodeError,
    Decoder,
    ErrorCode,
    ErrorReport,
    Event,
    Frame,
    InputCause,
    InputChange,
    Report,
    State,
    StatusReport,
)
from ..protocol.constants import PROTOCOL_VERSION, is_sequenced
from .errors import AlarmError, BoardReset, FirmwareError, LinkError, ProtocolVersionError
from .stats import LinkStats
from .window import SendWindow

# ERRORs about a frame damaged on the wire (PROTOCOL.md §2): nothing in it could be trusted, not
# even its seq.
FRAMING_ERRORS = frozenset(
    {
        ErrorCode.FRAME_TOO_LONG,
        ErrorCode.FRAME_TOO_SHORT,
        ErrorCode.BAD_COBS,
        ErrorCode.BAD_CRC,
        ErrorCode.RX_OVERRUN,
    }
)


@dataclass
class Waiter:
    """An immediate request waiting for the report that answers it."""

    seq: int
    request_type: int
    reply_type: int
    reply: Report | None = None
    error: ErrorReport | None = None
    # an answer this host cannot decode: another protocol version's layout
    unreadable: str | None = None

    @property
    def answered(self) -> bool:
        return self.reply is not None or self.error is not None or self.unreadable is not None

    def raise_refusal(self, name: str) -> None:
        """An ERROR for the request, or an answer this host cannot decode (another protocol
        version's)."""
        if self.error is not None:
            raise FirmwareError(self.error)
        if self.unreadable is not None:
            raise ProtocolVersionError(
                f"the firmware's answer to {name} does not decode ({self.unreadable}): "
                f"it speaks another protocol version than this host's {PROTOCOL_VERSION}"
            )


class Inbox:
    def __init__(self, window: SendWindow, stats: LinkStats) -> None:
        self.window = window
        self.stats = stats
        self.decoder = Decoder("to_host")
        self.generation = 0  # restarts of the stream (STOP, HOLD, a hold the firmware began) so far
        self.queue_capacity: int | None = None  # known once connected
        self.waiter: Waiter | None = None
        self.failure: LinkError | None = None  # raised by every call until the next restart
        # a STOP or HOLD is on its way: ACKs and alarms are about dropped frames
        self.stopping = False
        self.done16 = 0
        self.done_total = 0  # segments completed since reset (ACK `done` unwrapped)
        self.expected_done = 0  # segments completed once everything accepted has run
        self.latest: dict[type, Report] = {}  # the latest unsolicited report of each class
        self.counts: defaultdict[type, int] = defaultdict(int)
        self.input_changes: deque[InputChange] = deque(maxlen=256)  # the latest EVENT INPUT reports
        # holds the firmware began itself (a PROBE's edge, the feed hold button)
        self.held_by_input = 0
        self.starved = False  # the latest status said STARVED
        self.last_frame_at = 0.0  # clock time of the last good frame received
        # Everything the board sent before this clock time has been read and applied: when the
        # reader's latest read but one began. A host that was frozen (stopped, swapped out,
        # starved of CPU) has not looked at the port meanwhile: its pause is no silence of the
        # board's.
        self.seen_until = 0.0
        self._look_began = 0.0
        self.want_status = False  # the writer sends a STATUS: something needs explaining
        # BUSY or ALARM_ACTIVE for a frame of ours, until a status explains it
        self.refused: ErrorReport | None = None
        # the board's latest STATUS_REPORT (or answer to STOP, HOLD)
        self.last_status: StatusReport | None = None

    def look(self, now: float) -> None:
        """The reader begins a read at `now`: the one before it ended, and what it read is
        applied."""
        self.seen_until, self._look_began = self._look_began, now

    def receive(self, data: bytes, now: float) -> list[Report]:
        """Decode and apply what the reader read at `now`; returns the reports that on_report
        callbacks want."""
        self.stats.bytes_received += len(data)
        notify: list[Report] = []
        for item in self.decoder.feed(data):
            if isinstance(item, DecodeError):
                self.stats.decode_errors += 1
                waiter = self.waiter
                if waiter is not None and (item.frame_type, item.frame_seq) == (
                    waiter.reply_type,
                    waiter.seq,
                ):
                    waiter.unreadable = item.detail
                continue
            self.last_frame_at = now
            self.stats.frames_received += 1
            message = item.message
            if self.apply(item) and isinstance(message, Report):  # apply() wants only reports
                notify.append(message)
        return notify

    def last_alarm(self) -> Alarm | None:
        alarm = self.latest.get(Alarm)
        return alarm if isinstance(alarm, Alarm) else None

    def fail(self, failure: LinkError) -> None:
        if self.failure is None:
            self.failure = failure

    def resync(self, status: StatusReport) -> None:
        """Adopt a status taken with nothing in flight (connection, restart, rest after a hold)."""
        assert self.queue_capacity is not None
        self.window.reset(status.next_seq, self.queue_capacity - status.queue_fill)
        self.done_total = status.segments_done
        self.done16 = status.segments_done & 0xFFFF
        self.expected_done = status.segments_done + status.queue_fill
        self.refused = None

    def _keep(self, m: Alarm | Event) -> None:
        """The latest report under every class it is (a HoldDoneAlong is a HoldDone too), and its
        count."""
        for cls in type(m).__mro__[: type(m).__mro__.index(Report)]:
            self.latest[cls] = m
            self.counts[cls] += 1

    def apply(self, frame: Frame) -> bool:
        """Apply one report; True if on_report callbacks want it."""
        m = frame.message
        if isinstance(m, Ack):
            self._on_ack(m, frame.seq)
            return m.reason == AckReason.SPACE
        if isinstance(m, ErrorReport):
            self._on_error(m)
            return True
        if isinstance(m, (Alarm, Event)):
            self._keep(m)
            if isinstance(m, InputChange):
                self.input_changes.append(m)
                if m.cause in (InputCause.TRIGGER, InputCause.FEED_HOLD):
                    self._held_by_input()
            if isinstance(m, Alarm):
                self.stats.alarms += 1
                if not self.stopping:
                    self.fail(AlarmError(m))
            return True
        waiter = self.waiter
        if (
            waiter is not None
            and frame.seq == waiter.seq
            and m.CODE == waiter.reply_type
            and isinstance(m, Report)  # a reply's code is a report's
        ):
            waiter.reply = m
        if isinstance(m, StatusReport):
            self._check_reset(m)
            self.last_status = m
            self.done_total = m.segments_done
            self.done16 = m.segments_done & 0xFFFF
            starved, self.starved = self.starved, m.state == State.STARVED
            if self.starved and not starved and not self.stopping:
                self._starved()
            if not self.stopping and self.queue_capacity is not None:  # repairs a lost SPACE ack
                self.expected_done += self.window.on_status(
                    m.next_seq, self.queue_capacity - m.queue_fill
                )
                self._explain(m)
        return False

    def _check_reset(self, status: StatusReport) -> None:
        """The board's segments_done and motion_ticks only grow (motion_ticks wraps after 2^32
        ticks): one that went back is a board reset, which fails the link whatever else it was
        doing."""
        last = self.last_status
        if last is None:
            return
        ticks_back = (status.motion_ticks - last.motion_ticks) & 0xFFFFFFFF >= 1 << 31
        if status.segments_done < max(self.done_total, last.segments_done) or ticks_back:
            if not isinstance(self.failure, BoardReset):
                self.failure = BoardReset(max(self.done_total, last.segments_done), last, status)

    def _explain(self, status: StatusReport) -> None:
        """A status while streaming: an alarm whose report was lost, or what a refusal was about."""
        if self.failure is not None:
            return
        streaming = (
            self.window.in_flight > 0
            or self.expected_done > self.done_total
            or self.refused is not None
        )
        if status.state == State.ALARM and status.alarm is not None and streaming:
            self.fail(
                AlarmError(
                    Alarm(
                        code=status.alarm,
                        motion_ticks=status.motion_ticks,
                        position=status.position,
                    )
                )
            )
        elif self.refused is not None and status.state != State.HOLDING:
            self.fail(FirmwareError(self.refused))
        # HOLDING without a HOLD from here: a stop the firmware began itself (an underrun); STARVED
        # follows.

    def _held_by_input(self) -> None:
        """The firmware began a hold itself, at an input (a PROBE's edge, the feed hold button):
        what is queued or in flight will not run (segments arriving while it holds are refused,
        BUSY), so the stream restarts as at a STOP or HOLD; a waiter resyncs once it is at rest
        (inputs.wait_rest)."""
        self.generation += 1
        self.window.restart()
        self.held_by_input += 1

    def _starved(self) -> None:
        """The queue ran dry while moving and the firmware stopped (STARVED): it refuses every
        segment until a HOLD (or STOP), so the stream restarts as at a hold; whoever streams takes
        it up with HOLD."""
        self.generation += 1
        self.window.restart()
        self.refused = None  # the BUSY refusals were this stop's
        self.stats.starvations += 1

    def _on_ack(self, ack: Ack, seq: int) -> None:
        self.done_total += (ack.done - self.done16) & 0xFFFF
        self.done16 = ack.done
        if ack.reason in (AckReason.GAP, AckReason.PARKED):
            self.stats.gaps += 1
        elif ack.reason == AckReason.DUPLICATE:
            self.stats.duplicates += 1
        elif ack.reason == AckReason.QUEUE_FULL:
            self.stats.queue_full += 1
        if not self.stopping:
            self.expected_done += self.window.on_ack(ack.next_seq, ack.free, ack.reason, seq)

    def _on_error(self, error: ErrorReport) -> None:
        self.stats.errors += 1
        waiter = self.waiter
        if (
            waiter is not None
            and error.frame_type == waiter.request_type
            and error.frame_seq == waiter.seq
        ):
            waiter.error = error
            return
        if error.code in FRAMING_ERRORS and not self.stopping:
            self.window.on_damaged()
            return
        if (
            self.window.holds(error.frame_seq)
            and is_sequenced(error.frame_type)
            and not self.stopping
        ):
            if error.code in (ErrorCode.BUSY, ErrorCode.ALARM_ACTIVE):
                # Usually a stop the firmware began (an underrun, a silent host): a status says
                # which.
                self.refused = self.refused or error
                self.want_status = True
            else:
                self.fail(FirmwareError(error))
        # Framing errors (a frame damaged on the wire) are repaired by go-back-N; errors about
        # frames this link did not send (another writer on the line) are only counted.
