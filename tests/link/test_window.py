"""The send window alone: no port, no threads, a clock the test turns by hand."""

from __future__ import annotations

import time

import pytest
from window_model import scenario

from quadstep.link import LinkTimeout, SendWindow
from quadstep.protocol import AckReason

SCENARIOS = 10_000


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def window(free: int = 4, base: int = 0, rto: float = 1.0, retries: int = 8) -> tuple[SendWindow, Clock]:
    clock = Clock()
    w = SendWindow(clock, rto=rto, retries=retries)
    w.reset(base, free)
    return w, clock


def push(w: SendWindow, count: int, segments: int = 1) -> list[int]:
    return [w.push(bytes((w.next_seq,)), segments) for _ in range(count)]


def seqs(frames: list[bytes]) -> list[int]:
    return [f[0] for f in frames]


def test_ten_thousand_faulty_scenarios_deliver_every_segment_exactly_once_in_order() -> None:
    start = time.perf_counter()
    outcomes = [scenario(seed) for seed in range(SCENARIOS)]
    seconds = time.perf_counter() - start
    for seed, o in enumerate(outcomes):
        assert o.executed == list(range(o.segments)), (seed, o)
        assert o.in_flight == 0 and o.accepted == o.segments, (seed, o)
    # The faults did happen, in every kind, in many scenarios.
    for kind in ("lost", "duplicated", "overtaken"):
        for direction in (0, 1):
            hit = sum(1 for o in outcomes if getattr(o, kind)[direction])
            assert hit > SCENARIOS // 10, (kind, direction, hit)
    assert sum(o.retransmits for o in outcomes) > SCENARIOS
    frames = sum(o.segments for o in outcomes)
    print(f"\nsend window: {SCENARIOS} scenarios ({frames} segments, "
          f"{sum(o.retransmits for o in outcomes)} retransmits) in {seconds:.2f} s, no port")


def test_the_window_holds_what_the_firmware_has_room_for() -> None:
    w, _ = window(free=3, base=250)
    assert push(w, 3) == [250, 251, 252]
    assert not w.room() and w.in_flight == 3
    assert seqs(w.due()) == [250, 251, 252]
    assert w.due() == []  # written once
    assert w.on_ack(252, 2, AckReason.ACCEPTED) == 2
    assert w.in_flight == 1 and w.room() and w.holds(252) and not w.holds(251)


def test_frames_taken_ahead_wait_for_their_slots_and_go_out_in_order_as_reports_free_them() -> None:
    """`ahead`: the window takes frames beyond the board's free slots, writes none of them before a
    report frees its slots, and says so (pending) only once one may go."""
    w, _ = window(free=2)
    assert push(w, 2) == [0, 1]
    assert not w.room() and w.room(ahead=3)
    push(w, 3)
    assert not w.room(ahead=3) and w.in_flight == 5
    assert seqs(w.due()) == [0, 1] and not w.pending  # frames 2-4 wait for slots
    w.on_ack(2, 0, AckReason.ACCEPTED)
    assert w.due() == [] and not w.pending
    w.on_ack(2, 2, AckReason.SPACE)  # two segments finished
    assert w.pending and seqs(w.due()) == [2, 3] and not w.pending
    w.on_ack(4, 1, AckReason.ACCEPTED)  # they were taken; one slot still free
    assert w.pending and seqs(w.due()) == [4]
    assert w.on_ack(5, 0, AckReason.ACCEPTED) == 1 and w.in_flight == 0


def test_sequence_numbers_wrap_past_255() -> None:
    w, _ = window(free=4, base=254)
    assert push(w, 4) == [254, 255, 0, 1]
    w.due()
    assert w.on_ack(1, 4, AckReason.ACCEPTED) == 3
    assert w.base == 1 and w.next_seq == 2


def test_a_gap_goes_back_once_per_next_seq() -> None:
    w, _ = window(free=4)
    push(w, 3)
    w.due()
    assert w.on_ack(0, 4, AckReason.GAP) == 0  # frame 0 lost: 1 arrived first
    assert seqs(w.due()) == [0, 1, 2]
    w.on_ack(0, 4, AckReason.GAP)  # the GAP for 2 of the first round: already handled
    assert w.due() == []
    assert w.stats.retransmits == 3


def test_the_retransmission_timeout_resends_everything_unacknowledged() -> None:
    w, clock = window(free=4, rto=0.25)
    push(w, 2)
    w.due()
    assert w.deadline() == 0.25
    clock.now = 0.24
    assert w.due() == []
    clock.now = 0.25
    assert seqs(w.due()) == [0, 1]
    assert (w.stats.timeouts, w.stats.retransmits) == (1, 2)


def test_a_frame_resent_too_often_is_a_link_timeout() -> None:
    w, clock = window(free=4, rto=1.0, retries=2)
    push(w, 1)
    for _ in range(3):
        w.due()
        clock.now += 1.0
    with pytest.raises(LinkTimeout, match="frame seq 0 unacknowledged after 2 resends"):
        w.due()


def test_a_lost_ack_costs_a_duplicate_and_counts_the_segment_once() -> None:
    w, clock = window(free=4)
    push(w, 1)
    w.due()
    clock.now = 1.0
    assert seqs(w.due()) == [0]  # the ACK was lost: resent
    assert w.on_ack(1, 3, AckReason.DUPLICATE) == 1  # the copy's answer still says frame 0 was taken
    assert w.in_flight == 0


def test_a_rejected_frame_is_not_counted_as_accepted() -> None:
    w, _ = window(free=4)
    push(w, 2)
    w.due()
    assert w.on_ack(2, 4, AckReason.REJECTED) == 1  # frame 0 accepted (its ACK lost), frame 1 refused


def test_set_position_frames_take_no_queue_slot_in_the_count() -> None:
    w, _ = window(free=4)
    push(w, 1, segments=0)
    push(w, 1)
    w.due()
    assert w.on_ack(2, 3, AckReason.ACCEPTED) == 1


def test_queue_full_resends_what_was_written_even_without_room_but_holds_back_new_frames() -> None:
    w, _ = window(free=2)
    push(w, 2)
    w.due()
    assert w.on_ack(1, 0, AckReason.QUEUE_FULL) == 1  # frame 0 taken, frame 1 refused: no slot left
    assert seqs(w.due()) == [1]  # written before: the firmware answers it again, whatever its room
    w.on_ack(2, 1, AckReason.ACCEPTED)
    push(w, 1)
    w.on_ack(2, 0, AckReason.SPACE)
    assert w.due() == [] and w.stalled  # a new frame needs a slot
    assert w.on_status(2, 1) == 0
    assert seqs(w.due()) == [2]


def test_a_lost_space_ack_is_repaired_by_a_status() -> None:
    w, _ = window(free=1)
    push(w, 1)
    w.due()
    w.on_ack(1, 0, AckReason.ACCEPTED)
    assert w.stalled and not w.room()  # the SPACE ack that would follow is lost
    w.on_status(1, 1)
    assert w.room() and not w.stalled


def test_resend_marks_one_frame_alone() -> None:
    """What a selective repeat needs: one damaged frame written again, not the frames after it."""
    w, _ = window(free=4)
    push(w, 3)
    w.due()
    w.resend(1)
    assert seqs(w.due()) == [1]
    w.resend(7)  # not in the window: nothing
    assert w.due() == []


def test_restart_drops_every_frame_and_ignores_their_late_acks() -> None:
    w, _ = window(free=4, base=10)
    push(w, 3)
    w.due()
    assert w.restart() == 13  # the seq a STOP or HOLD carries
    assert w.in_flight == 0 and w.deadline() is None
    assert w.on_ack(12, 4, AckReason.ACCEPTED) == 0  # about a dropped frame
    assert w.base == 13


def test_last_tx_tells_how_long_the_line_has_been_idle() -> None:
    w, clock = window(free=4)
    assert w.last_tx == float("-inf")
    push(w, 1)
    clock.now = 3.0
    w.due()
    assert w.last_tx == 3.0
