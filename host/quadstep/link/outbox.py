"""What the writer thread writes next: immediate requests first, then the sequenced frames the
window says are due, then a STATUS when one is wanted: the window has stayed closed (a SPACE ack
lost), the line has been quiet on our side while the board may be moving (the keep-alive that the
firmware's WATCHDOG needs), or an ERROR asked for an explanation (an alarm whose report was lost).

It also notices a silent board: while anything is outstanding (a frame unacknowledged, a segment the
board has not finished), no good frame back for `silence` seconds fails the link with BoardSilent,
which says what the board last confirmed. Those seconds are the reader's: they count up to where it
has read the port, so a host that was frozen longer than that (stopped, asleep, starved of CPU)
first reads what the board sent meanwhile.

An Outbox is shared state: every method and field is used with the link's condition held.
"""

from __future__ import annotations

from collections import deque

from ..protocol import Status, encode
from .errors import BoardSilent, LinkTimeout, known_text
from .port_open import READ_TIMEOUT
from .reports import Inbox
from .stats import LinkStats
from .window import SendWindow

KEEPALIVE = 0.1  # s without a write, while the board may be moving, before a STATUS
STALL_POLL = 0.05  # s without a report, while the window is closed, before a STATUS
SILENCE = 1.5  # s without a good frame, while something is outstanding, before the link gives up


class Outbox:
    def __init__(
        self,
        window: SendWindow,
        inbox: Inbox,
        stats: LinkStats,
        poll_interval: float,
        silence: float = SILENCE,
    ) -> None:
        self.window = window
        self.inbox = inbox
        self.stats = stats
        self.poll_interval = poll_interval
        self.silence = silence
        # immediate requests, written before any sequenced frame
        self.urgent: deque[bytes] = deque()
        self.request_seq = 0x40
        self.last_poll = 0.0
        self.last_write = 0.0
        # When the board last began to owe an answer: a line quiet while nothing was owed (a job
        # paused at a prompt) is not a silent board, so the silence counts from here or from the
        # last frame back.
        self.owed_since = 0.0
        self.owing = False

    def next_request_seq(self) -> int:
        self.request_seq = (self.request_seq + 1) & 0xFF
        return self.request_seq

    def take(self, now: float) -> bytes:
        """Everything to write now (b"" for nothing); a frame resent too often, or a silent board,
        fails the link."""
        out = bytearray()
        while self.urgent:
            data = self.urgent.popleft()
            self.stats.frames_sent += data != b"\x00"
            out += data
        inbox = self.inbox
        if inbox.failure is None and not inbox.stopping:
            try:
                frames = self.window.due()
            except LinkTimeout as exc:
                inbox.fail(exc)
                frames = []
            for data in frames:
                out += data
            self.stats.frames_sent += len(frames)
            if not self._outstanding():
                self.owing = False
            elif not self.owing:
                self.owing, self.owed_since = True, now
            if self._outstanding() and inbox.seen_until - self._heard_at() >= self.silence:
                inbox.fail(BoardSilent(self._silence_text()))
            elif inbox.want_status or self._stalled(now) or (not out and self._keepalive_due(now)):
                inbox.want_status = False
                self.last_poll = now
                self.stats.frames_sent += 1
                out += encode(Status(), self.next_request_seq())
        if out:
            self.last_write = now
        self.stats.bytes_sent += len(out)
        return bytes(out)

    def writable(self) -> bool:
        """Whether take() may have something now that a report brought (the writer is not woken
        for every report): a request, a frame to write again or with slots free now, a STATUS
        wanted, or a failure to tell."""
        inbox = self.inbox
        return bool(
            self.urgent or self.window.pending or inbox.want_status or inbox.failure is not None
        )

    def wait_time(self, now: float) -> float:
        """How long the writer may sleep before take() can have something (unless woken)."""
        waits = [self.poll_interval]
        deadline = self.window.deadline()
        if deadline is not None:
            waits.append(deadline - now)
        if self._outstanding():
            # past the silence limit, until the reader has looked at the port since it
            silent_at = max(self._heard_at() + self.silence - now, READ_TIMEOUT)
            waits += [self.last_write + KEEPALIVE - now, silent_at]
        if self._stall_possible():
            waits.append(max(self.inbox.last_frame_at, self.last_poll) + STALL_POLL - now)
        return max(0.001, min(waits))

    def _outstanding(self) -> bool:
        """Something the board owes an answer for: a frame unacknowledged, a segment not yet
        finished, or a refusal (BUSY) no status has explained yet — refused while the board braked,
        it is explained only once the board is at rest, so the keep-alive asks again until then."""
        return self.inbox.queue_capacity is not None and (
            self.window.in_flight > 0
            or self.inbox.expected_done > self.inbox.done_total
            or self.inbox.refused is not None
        )

    def _heard_at(self) -> float:
        """Where the silence counts from: the last good frame, or when the board began to owe
        one."""
        return max(self.inbox.last_frame_at, self.owed_since if self.owing else 0.0)

    def _keepalive_due(self, now: float) -> bool:
        return self._outstanding() and now - self.last_write >= KEEPALIVE

    def _stall_possible(self) -> bool:
        return self.inbox.queue_capacity is not None and self.window.stalled

    def _stalled(self, now: float) -> bool:
        """The window closed with nothing awaiting an ACK, and no report for a while (a lost SPACE
        ack)."""
        return (
            self._stall_possible()
            and now - max(self.inbox.last_frame_at, self.last_poll) >= STALL_POLL
        )

    def _silence_text(self) -> str:
        inbox, window = self.inbox, self.window
        return (
            f"the board has not answered for {self.silence:g} s (is it powered, "
            "connected, running?): the last frame it confirmed was seq "
            f"{(window.base - 1) & 0xFF}; {inbox.done_total} segments done, "
            f"{max(0, inbox.expected_done - inbox.done_total)} more accepted, {window.in_flight} "
            "frames unacknowledged" + known_text(inbox.last_status, inbox.last_alarm())
        )
