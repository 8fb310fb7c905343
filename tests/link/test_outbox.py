"""The writer's choices (link/outbox.py), with a clock of the test's own and no port: a refusal the board made
while it braked (an underrun's stop: HOLDING, then STARVED) keeps the keep-alive asking until a status explains
it, so a wait for the frames to drain never waits forever."""

from __future__ import annotations

from quadstep.link.outbox import KEEPALIVE, Outbox
from quadstep.link.reports import Inbox
from quadstep.link.stats import LinkStats
from quadstep.link.window import SendWindow
from quadstep.protocol import AckReason, ErrorCode, ErrorReport, State, StatusReport
from quadstep.protocol.codec import decode

NOW = 100.0


def status(state: State) -> StatusReport:
    return StatusReport(state=state, alarm=None, queue_fill=0, next_seq=5, segments_done=10, motion_ticks=1000,
                        rx_overrun=0, bad_frame=0, bad_crc=0, seq_gap=0, seq_dup=0, rejected=1,
                        position=(0, 0, 0, 0))


def written(outbox: Outbox, now: float) -> list[int]:
    """The types of the frames the writer writes at `now`."""
    data = outbox.take(now)
    return [decode(chunk + b"\x00", "to_firmware").message.CODE for chunk in data.split(b"\x00") if chunk]


def connected() -> Outbox:
    """The writer's choices for a board of 14 slots at rest, heard from at NOW."""
    stats = LinkStats()
    window = SendWindow(clock=lambda: NOW, stats=stats)
    inbox = Inbox(window, stats)
    inbox.queue_capacity = 14
    inbox.resync(status(State.IDLE))
    inbox.last_frame_at = NOW
    return Outbox(window, inbox, stats, poll_interval=0.05)


def test_a_refusal_during_a_stop_is_asked_about_until_the_board_is_at_rest() -> None:
    outbox = connected()
    inbox = outbox.inbox
    inbox.refused = ErrorReport(code=ErrorCode.BUSY, frame_type=0x18, frame_seq=4, field=None, axis=None)
    inbox.want_status = True
    assert written(outbox, NOW) == [0x02]  # a STATUS asks why
    inbox.last_status = status(State.HOLDING)  # the answer: still braking, nothing explained yet
    inbox.last_frame_at = NOW + 0.01
    assert written(outbox, NOW + 0.01) == []
    assert written(outbox, NOW + 0.01 + KEEPALIVE) == [0x02]  # and asks again


def test_a_report_wakes_the_writer_only_for_what_it_makes_due() -> None:
    outbox = connected()
    window, inbox = outbox.window, outbox.inbox
    segment = bytes.fromhex("0510000a00")  # any bytes: the window never reads them
    window.push(segment, 1)
    assert outbox.writable()  # a frame to write
    assert outbox.take(NOW) == segment
    assert not outbox.writable()  # in flight: an ACK of it, or a SPACE ack, brings nothing to write
    window.on_ack(next_seq=window.base, free=14, reason=AckReason.GAP)
    assert outbox.writable()  # a GAP: the frame is written again
    assert outbox.take(NOW) == segment
    window.on_ack(next_seq=(window.base + 1) & 0xFF, free=14, reason=AckReason.ACCEPTED)
    assert not outbox.writable()
    inbox.want_status = True  # an ERROR asked for an explanation
    assert outbox.writable()
