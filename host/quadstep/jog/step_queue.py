"""Incremental jog presses waiting for the machine: one press is one step, and presses beyond what
the machine can run soon (a held key's repeats) are dropped rather than queued.

A press is taken while nothing waits, or while what waits would run for less than `limit` seconds
(its steps' durations at the jog speed, estimated as trapezoids), so quick taps of a small step all
count and a held key with a 10 mm step queues one step behind the one that moves, not twenty.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

QUEUE_LIMIT = 0.5  # s of waiting jog motion beyond which a press is dropped


@dataclass(frozen=True)
class QueuedStep:
    axis: int
    direction: int
    distance: float  # mm
    seconds: float  # estimated duration


def step_seconds(distance: float, speed: float, accel: float) -> float:
    """A rest-to-rest move's duration at `speed` (mm/s) with `accel` (mm/s²) ramps."""
    if distance * accel >= speed * speed:
        return distance / speed + speed / accel
    return 2.0 * math.sqrt(distance / accel)


class StepQueue:
    """Thread-safe: offer() from the UI, take() from the worker that runs the step, clear() on a
    stop."""

    def __init__(self, limit: float = QUEUE_LIMIT) -> None:
        self.limit = limit
        self._lock = threading.Lock()
        self._waiting: list[QueuedStep] = []
        self._running: QueuedStep | None = None
        self.dropped = 0  # presses dropped since the last clear()

    def offer(self, step: QueuedStep) -> bool:
        """Queue `step` unless what already waits is too long; False: dropped."""
        with self._lock:
            if self._waiting and sum(s.seconds for s in self._waiting) >= self.limit:
                self.dropped += 1
                return False
            self._waiting.append(step)
            return True

    def take(self, step: QueuedStep) -> bool:
        """The worker starts `step`; False when a stop cleared it meanwhile."""
        with self._lock:
            for i, waiting in enumerate(self._waiting):
                if waiting is step:
                    del self._waiting[i]
                    self._running = step
                    return True
            return False

    def done(self, step: QueuedStep) -> None:
        with self._lock:
            if self._running is step:
                self._running = None

    def clear(self) -> None:
        with self._lock:
            self._waiting.clear()
            self.dropped = 0

    def queued_mm(self) -> dict[int, float]:
        """Signed distance per axis of the step that moves and those that wait, mm."""
        with self._lock:
            out: dict[int, float] = {}
            for s in ([self._running] if self._running is not None else []) + self._waiting:
                out[s.axis] = out.get(s.axis, 0.0) + s.direction * s.distance
            return out
