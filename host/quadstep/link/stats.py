"""Counters of everything a link did."""

from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass
class LinkStats:
    """`retransmits` counts frames written again; `timeouts` retransmission timeouts and unanswered
    requests."""

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
    # underruns the board stopped at (STARVED) while streaming; each restarted the stream
    starvations: int = 0

    def as_dict(self) -> dict[str, int]:
        return asdict(self)
