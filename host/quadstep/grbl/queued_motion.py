"""How long the lines waiting for a job would keep the machine moving, roughly: each move at its
feed, a rapid at the slowest axis's top speed, no acceleration, and the dwells. A sender's stream
starts its job once they outlast what a running job keeps back from the board (open_end.py):
started with less, the job would feed the board only a trickle until enough lines came, and a
queue of short segments runs dry through any pause of the host."""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..config import MachineConfig
from ..machine.open_end import FLOOR_S, kept_back_s
from ..planner.program import Dwell, Item, LinearMove


class QueuedMotion:
    """The motion of the lines queued since the last clear(), in seconds (`seconds`), against
    the least a job should start with (`enough`)."""

    def __init__(self, config: MachineConfig) -> None:
        self._rapid = min(axis.max_speed for axis in config.axes)
        # the kept-back end, and the floor of motion the board is sent before it while it runs
        self._start_s = kept_back_s(config) + FLOOR_S
        self._last: tuple[float, ...] | None = None  # the last target: the next move starts there
        self.seconds = 0.0

    @property
    def enough(self) -> bool:
        return self.seconds >= self._start_s

    def add(self, items: Iterable[Item]) -> None:
        for item in items:
            if isinstance(item, LinearMove):
                if self._last is not None:
                    self.seconds += math.dist(item.target, self._last) / (item.feed or self._rapid)
                self._last = item.target
            elif isinstance(item, Dwell):
                self.seconds += item.seconds

    def clear(self) -> None:
        """The queued lines were taken (the last target is kept)."""
        self.seconds = 0.0
