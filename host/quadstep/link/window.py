"""The send window of sequenced frames (PROTOCOL.md §3–4): a plain object, no I/O, no threads.

It numbers the frames, keeps each one until an ACK's `next_seq` passes it,
decides what to write and when, and counts what it did. Time comes from an
injected clock, so the window is tested on its own, without any port
(tests/link/test_window.py); Link calls it under its one lock.

Each frame is `pending` until it is written. Retransmission is go-back-N: an
ACK GAP or QUEUE_FULL (once per `next_seq`), or the retransmission timeout,
marks every unacknowledged frame pending again, and `due()` writes pending
frames in sequence order: a frame written before needs no room to be written
again (the firmware answers a copy it has with DUPLICATE, and a frame it has
no room for with QUEUE_FULL), a new one needs a free slot. `resend(seq)`
marks one frame alone, which is what a selective repeat (a NAK naming one
damaged frame) needs; `last_tx` tells an idle line, for a keep-alive.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..protocol import AckReason
from ..protocol.constants import MAX_IN_FLIGHT
from .errors import LinkTimeout
from .stats import LinkStats

Clock = Callable[[], float]


# s: the retransmission timeout never goes below this (a busy host answers late), however short the
# round trip
MIN_RTO = 0.05
GIVE_UP = 2.0  # s: a frame resent `retries` times is given up only once it has waited this long too


class _Frame:
    __slots__ = (
        "seq",
        "data",
        "segments",
        "transmissions",
        "pending",
        "first_sent",
        "sent_at",
        "order",
        "parked",
    )

    def __init__(self, seq: int, data: bytes, segments: int) -> None:
        self.seq = seq
        self.data = data
        self.segments = segments  # queue slots it takes; counted as accepted when acknowledged
        self.transmissions = 0
        self.pending = True
        self.first_sent = 0.0
        self.sent_at = 0.0
        self.order = 0  # the window's write count at its last write: the line keeps this order
        self.parked = False  # the firmware keeps it until the frames before it arrive (ACK PARKED)


class SendWindow:
    """Sequenced frames from `base` (the firmware's next_seq) on; `free` slots as last reported."""

    def __init__(
        self,
        clock: Clock,
        rto: float = 0.25,
        retries: int = 8,
        stats: LinkStats | None = None,
        max_in_flight: int = MAX_IN_FLIGHT,
    ) -> None:
        self.clock = clock
        self.max_rto = rto  # the timeout before any round trip is measured, and its ceiling
        self.rto = rto  # now: from the measured round trips (RFC 6298), doubled by each timeout
        self._srtt: float | None = None
        self._rttvar = 0.0
        self.retries = retries
        self.stats = stats if stats is not None else LinkStats()
        self.max_in_flight = max_in_flight
        self.base = 0
        self.free = 0
        self.last_tx = -math.inf  # clock time of the last write
        self._frames: list[_Frame] = []
        self._slots = 0  # queue slots the frames in the window take
        self._first_pending = 0  # every frame before this index has been written
        self._written = 0  # frames written and not yet acknowledged
        self._last_progress = 0.0  # last ACK that advanced, or first write of the frame at base
        self._gap_handled_for: int | None = None
        self._writes = 0

    # --- the firmware's state -----------------------------------------------------------------

    def reset(self, next_seq: int, free: int) -> None:
        """Adopt the firmware's next_seq and free slots (a connection, or the answer to
        STOP/HOLD)."""
        self._drop()
        self.base = next_seq
        self.free = free

    def restart(self) -> int:
        """Drop every frame, unsent or unacknowledged; returns the seq that a STOP or HOLD must
        carry."""
        seq = self.next_seq
        self._drop()
        self.base = seq
        return seq

    def on_status(self, next_seq: int, free: int) -> int:
        """A STATUS report's next_seq and free slots (capacity − queue fill): like a SPACE ack, it
        repairs a lost one. Returns the segment frames it acknowledges as accepted."""
        return self.on_ack(next_seq, free, AckReason.SPACE)

    @property
    def stalled(self) -> bool:
        """Nothing written awaits an ACK and the firmware reported no free slot: only a SPACE ack
        (or a STATUS, if that ack was lost) can open the window again."""
        return not self._written and self.free == 0

    # --- frames -------------------------------------------------------------------------------

    @property
    def next_seq(self) -> int:
        """The seq the next pushed frame gets."""
        return (self.base + len(self._frames)) & 0xFF

    @property
    def in_flight(self) -> int:
        """Frames pushed and not yet acknowledged."""
        return len(self._frames)

    def room(self, segments: int = 1, ahead: int = 0) -> bool:
        """Whether one more frame, taking `segments` queue slots, fits the flow-control window
        (every frame counts as at least one slot, as the firmware's free count does for a sequence
        of single frames): the board's free slots, and `ahead` more that it waits in the window
        for (written as soon as a report frees them)."""
        return (
            len(self._frames) < self.max_in_flight
            and self._slots + max(1, segments) <= self.free + ahead
        )

    def holds(self, seq: int) -> bool:
        """Whether frame `seq` is in the window (pushed, not yet acknowledged)."""
        return (seq - self.base) & 0xFF < len(self._frames)

    def push(self, data: bytes, segments: int) -> int:
        """Queue the frame `data`, encoded with seq `next_seq`, that takes `segments` queue slots;
        returns that seq."""
        seq = self.next_seq
        self._frames.append(_Frame(seq, data, segments))
        self._slots += max(1, segments)
        return seq

    def resend(self, seq: int) -> None:
        """Write the unacknowledged frame `seq` again at the next due() (one frame, not
        go-back-N)."""
        index = (seq - self.base) & 0xFF
        if index < len(self._frames):
            self._mark_pending(index)

    # --- acknowledgements -------------------------------------------------------------------------

    def on_ack(self, next_seq: int, free: int, reason: AckReason, seq: int | None = None) -> int:
        """Apply an ACK (of frame `seq`); returns the segment frames it acknowledges as accepted."""
        frames = self._frames
        advance = (next_seq - self.base) & 0xFF
        if advance > len(frames):
            return 0  # about frames from before a restart
        if reason == AckReason.PARKED and seq is not None:
            self._parked(seq)
        accepted = 0
        last = advance - 1
        if advance and frames[last].transmissions == 1 and not frames[last].pending:
            self._sample_rtt(self.clock() - frames[last].sent_at)  # Karn: never from a resent frame
        for i in range(advance):
            frame = frames[i]
            if not frame.pending:
                self._written -= 1
            # Every frame an ACK passes was accepted but the one it answers with REJECTED (which
            # comes with an ERROR and stops the stream): a frame passed only by a later ACK, its
            # own lost, was accepted too.
            if i < last or reason != AckReason.REJECTED:
                accepted += frame.segments
            self._slots -= max(1, frame.segments)
        del frames[:advance]
        self._first_pending = max(0, self._first_pending - advance)
        self.base = next_seq
        self.free = free
        if advance:
            self._last_progress = self.clock()
            self._gap_handled_for = None
        if reason in (AckReason.GAP, AckReason.QUEUE_FULL) and self._gap_handled_for != next_seq:
            self._gap_handled_for = next_seq
            self._go_back(parked_too=False)
        return accepted

    def on_damaged(self) -> None:
        """The firmware got a frame it could not read (a framing ERROR: which frame, it cannot say).
        Any frame written and not yet acknowledged may be the one: write them again now, as for a
        GAP (once per next_seq), not at the timeout — with several segments a frame, one lost frame
        is often the last one in flight, and no GAP would come."""
        if self._written and self._gap_handled_for != self.base:
            self._gap_handled_for = self.base
            self._go_back(parked_too=False)

    # --- writing ---------------------------------------------------------------------------------

    def due(self) -> list[bytes]:
        """The frames to write now, in order; raises LinkTimeout for a frame resent `retries`
        times."""
        now = self.clock()
        if self._written and now >= self._last_progress + self.rto:
            self.stats.timeouts += 1
            self._gap_handled_for = None
            # back off until a round trip is measured again
            self.rto = min(self.max_rto, 2 * self.rto)
            self._go_back(parked_too=True)  # the firmware may have let parked frames go
        frames = self._frames
        stop = min(len(frames), self.max_in_flight)
        if self._first_pending >= stop:
            return []  # the usual case: everything written is still in flight
        out: list[bytes] = []
        slots = sum(max(1, f.segments) for f in frames[: self._first_pending])
        for i in range(self._first_pending, stop):
            frame = frames[i]
            slots += max(1, frame.segments)
            if not frame.pending:
                continue
            # a frame never written needs free slots
            if slots > self.free and not frame.transmissions:
                stop = i
                break
            if frame.transmissions > self.retries and now - frame.first_sent >= GIVE_UP:
                raise LinkTimeout(
                    f"frame seq {frame.seq} unacknowledged after {frame.transmissions - 1} resends "
                    f"over {now - frame.first_sent:.1f} s"
                )
            if frame.transmissions:
                self.stats.retransmits += 1
            else:
                frame.first_sent = now
            frame.sent_at = now
            self._writes += 1
            frame.order = self._writes
            frame.transmissions += 1
            frame.pending = False
            self._written += 1
            if i == 0:
                self._last_progress = now
            out.append(frame.data)
        self._first_pending = max(self._first_pending, stop)
        if out:
            self.last_tx = now
        return out

    @property
    def pending(self) -> bool:
        """A frame may be written now: again, or for the first time with its slots free."""
        index = self._first_pending
        if index >= min(len(self._frames), self.max_in_flight):
            return False
        if self._frames[index].transmissions:
            return True
        # frames go out in order: the first never written waits for the slots up to its own
        return sum(max(1, f.segments) for f in self._frames[: index + 1]) <= self.free

    def deadline(self) -> float | None:
        """The clock time at which due() will resend for the retransmission timeout, if frames
        wait."""
        return self._last_progress + self.rto if self._written else None

    # --- internals --------------------------------------------------------------------------------

    def _sample_rtt(self, rtt: float) -> None:
        """RFC 6298: smoothed round trip and its variation; the timeout four variations above."""
        if self._srtt is None:
            self._srtt, self._rttvar = rtt, rtt / 2
        else:
            self._rttvar = 0.75 * self._rttvar + 0.25 * abs(self._srtt - rtt)
            self._srtt = 0.875 * self._srtt + 0.125 * rtt
        self.rto = min(self.max_rto, max(MIN_RTO, self._srtt + 4 * self._rttvar))

    def _go_back(self, parked_too: bool) -> None:
        """Go-back-N: every unacknowledged frame is written again (but those the firmware keeps)."""
        for i, frame in enumerate(self._frames):
            if parked_too or not frame.parked:
                self._mark_pending(i)

    def _parked(self, seq: int) -> None:
        """Selective repeat: frame `seq` waits in the firmware for the ones before it. Those written
        before it and neither acknowledged nor kept were lost on the way (the line keeps the order):
        resend them."""
        index = (seq - self.base) & 0xFF
        if index >= len(self._frames):
            return
        kept = self._frames[index]
        kept.parked = True
        for i in range(index):
            frame = self._frames[i]
            if not frame.parked and not frame.pending and frame.order < kept.order:
                self._mark_pending(i)

    def _mark_pending(self, index: int) -> None:
        frame = self._frames[index]
        if not frame.pending:
            frame.pending = True
            self._written -= 1
        self._first_pending = min(self._first_pending, index)

    def _drop(self) -> None:
        self._frames.clear()
        self._slots = 0
        self._first_pending = 0
        self._written = 0
        self._gap_handled_for = None
