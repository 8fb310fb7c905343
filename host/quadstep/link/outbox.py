"""What the writer thread writes next: immediate requests first, then the sequenced frames the window
says are due, then a STATUS when the window has stayed closed too long (a lost SPACE ack).

An Outbox is shared state: every method and field is used with the link's condition held.
"""

from __future__ import annotations

from collections import deque

from ..protocol import Status, encode
from .errors import LinkTimeout
from .reports import Inbox
from .stats import LinkStats
from .window import SendWindow


class Outbox:
    def __init__(self, window: SendWindow, inbox: Inbox, stats: LinkStats, poll_interval: float) -> None:
        self.window = window
        self.inbox = inbox
        self.stats = stats
        self.poll_interval = poll_interval
        self.urgent: deque[bytes] = deque()  # immediate requests, written before any sequenced frame
        self.request_seq = 0x40
        self.last_rx = 0.0  # clock time of the last bytes received
        self.last_poll = 0.0

    def next_request_seq(self) -> int:
        self.request_seq = (self.request_seq + 1) & 0xFF
        return self.request_seq

    def take(self, now: float) -> bytes:
        """Everything to write now (b"" for nothing); a frame resent too often fails the link."""
        out = bytearray()
        while self.urgent:
            data = self.urgent.popleft()
            self.stats.frames_sent += data != b"\x00"
            out += data
        if self.inbox.failure is None and not self.inbox.stopping:
            try:
                frames = self.window.due()
            except LinkTimeout as exc:
                self.inbox.fail(exc)
                frames = []
            for data in frames:
                out += data
            self.stats.frames_sent += len(frames)
            if self._stalled(now):
                self.last_poll = now
                self.stats.frames_sent += 1
                out += encode(Status(), self.next_request_seq())
        self.stats.bytes_sent += len(out)
        return bytes(out)

    def wait_time(self, now: float) -> float:
        """How long the writer may sleep before take() can have something (unless woken)."""
        deadline = self.window.deadline()
        wait = self.poll_interval if deadline is None else min(self.poll_interval, deadline - now)
        return max(0.001, wait)

    def _stalled(self, now: float) -> bool:
        """The window closed with nothing awaiting an ACK, and no report for a while."""
        return (self.inbox.queue_capacity is not None and self.window.stalled
                and now - max(self.last_rx, self.last_poll) >= self.poll_interval)
