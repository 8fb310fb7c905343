"""The send window against a model of the firmware's sequencing (PROTOCOL.md §3–4) over a faulty line.

Pure Python and a simulated clock: no port, no threads. One `scenario(seed)`
draws a queue size, a number of segments, a first seq and fault rates
(frames lost, duplicated, delayed past each other; ACKs lost, duplicated,
reordered), runs the window until the model has executed every segment,
and returns what happened. Used by the unit test and the benchmark.
"""

from __future__ import annotations

import heapq
import random
from collections.abc import Callable
from dataclasses import dataclass

from quadstep.link.window import SendWindow
from quadstep.protocol import AckReason

RTO = 1.0
POLL = 2.0  # the link's STATUS poll when the window stays closed with nothing in flight
MAX_EVENTS = 100_000


class FirmwareModel:
    """next_seq, a queue of `capacity` slots, and the ACK for each frame as §3 says."""

    def __init__(self, next_seq: int, capacity: int) -> None:
        self.next_seq = next_seq
        self.capacity = capacity
        self.queued = 0
        self.executed: list[int] = []

    def receive(self, seq: int, index: int) -> tuple[int, int, AckReason]:
        delta = (seq - self.next_seq) & 0xFF
        if delta == 0:
            if self.queued == self.capacity:
                return self.ack(AckReason.QUEUE_FULL)
            self.queued += 1
            self.executed.append(index)
            self.next_seq = (self.next_seq + 1) & 0xFF
            return self.ack(AckReason.ACCEPTED)
        return self.ack(AckReason.GAP if delta <= 127 else AckReason.DUPLICATE)

    def finish_one(self) -> tuple[int, int, AckReason]:
        self.queued -= 1
        return self.ack(AckReason.SPACE)

    def ack(self, reason: AckReason) -> tuple[int, int, AckReason]:
        return self.next_seq, self.capacity - self.queued, reason


@dataclass
class Outcome:
    segments: int
    executed: list[int]  # the segments in the order the firmware model executed them
    accepted: int  # segments the window's ACK accounting counted as accepted
    in_flight: int  # frames left in the window at the end
    events: int
    retransmits: int
    faults: dict[str, float]
    lost: tuple[int, int]  # items lost on the line: frames, ACKs
    duplicated: tuple[int, int]
    overtaken: tuple[int, int]  # items that arrived before one sent ahead of them


INF = float("inf")
TO_FIRMWARE, TO_HOST = 0, 1


def scenario(seed: int) -> Outcome:
    rng = random.Random(seed)
    segments = rng.randint(1, 8)
    capacity = rng.randint(1, 8)
    first_seq = rng.randrange(256)
    faults = {
        "loss": rng.choice((0.0, 0.05, 0.2, 0.4)),
        "duplication": rng.choice((0.0, 0.1, 0.3)),
        "jitter": rng.choice((0.0, 0.05, 0.5, 2.0)),  # past 0.01 s between frames, they overtake each other
        "ack_loss": rng.choice((0.0, 0.05, 0.2, 0.4)),
        "ack_duplication": rng.choice((0.0, 0.1, 0.3)),
        "ack_jitter": rng.choice((0.0, 0.05, 0.5, 2.0)),
    }
    service = rng.choice((0.001, 0.05, 0.5))  # seconds a queued segment takes to run
    random_ = rng.random
    clock = [0.0]
    window = SendWindow(lambda: clock[0], rto=RTO, retries=1_000_000)
    window.reset(first_seq, capacity)
    firmware = FirmwareModel(first_seq, capacity)
    in_transit: list[tuple[float, int, int, object]] = []  # (arrival, order, direction, frame or ACK)
    push = heapq.heappush
    order = [0]
    lost, duplicated, overtaken, last_order = [0, 0], [0, 0], [0, 0], [0, 0]

    def line(direction: int, loss: float, duplication: float, jitter: float) -> Callable[[object], None]:
        """Each item is lost, delivered, or delivered twice, after a random delay (so items may overtake)."""

        def send(item: object) -> None:
            copies = 0 if random_() < loss else 2 if random_() < duplication else 1
            if copies != 1:
                (lost if copies == 0 else duplicated)[direction] += 1
            for _ in range(copies):
                order[0] += 1
                push(in_transit, (clock[0] + 0.01 + random_() * jitter, order[0], direction, item))

        return send

    to_firmware = line(TO_FIRMWARE, faults["loss"], faults["duplication"], faults["jitter"])
    to_host = line(TO_HOST, faults["ack_loss"], faults["ack_duplication"], faults["ack_jitter"])

    pushed = accepted = events = 0
    next_finish = next_poll = INF
    host_turn = True  # the host acts after its own events: an ACK, the retransmission timeout, a poll
    while (len(firmware.executed) < segments or window.in_flight) and events < MAX_EVENTS:
        events += 1
        if host_turn:
            while pushed < segments and window.room():
                window.push(bytes((window.next_seq, pushed)), 1)
                pushed += 1
            for data in window.due():
                to_firmware(data)
            if next_poll == INF and window.stalled:
                next_poll = clock[0] + POLL  # the link asks for STATUS when the window stays closed
        deadline = window.deadline()
        arrival = in_transit[0][0] if in_transit else INF
        now = min(arrival, next_finish, next_poll, INF if deadline is None else deadline)
        if now > clock[0]:
            clock[0] = now
        host_turn = True
        if now == arrival:
            _, sent_as, direction, item = heapq.heappop(in_transit)
            if sent_as < last_order[direction]:
                overtaken[direction] += 1
            last_order[direction] = max(last_order[direction], sent_as)
            if direction == TO_FIRMWARE:
                host_turn = False
                to_host(firmware.receive(item[0], item[1]))  # type: ignore[index]
                if firmware.queued and next_finish == INF:
                    next_finish = clock[0] + service
            else:
                accepted += window.on_ack(*item)  # type: ignore[misc]
        elif now == next_finish:
            host_turn = False
            to_host(firmware.finish_one())
            next_finish = clock[0] + service if firmware.queued else INF
        elif now == next_poll:
            next_poll = INF
            if window.stalled:  # the STATUS answer, taken now
                accepted += window.on_status(firmware.next_seq, firmware.capacity - firmware.queued)
    return Outcome(segments, firmware.executed, accepted, window.in_flight, events, window.stats.retransmits, faults,
                   tuple(lost), tuple(duplicated), tuple(overtaken))  # type: ignore[arg-type]
