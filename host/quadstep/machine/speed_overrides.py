"""The rapid and spindle overrides of a machine (planner/feed_override.py has the arithmetic): they
apply to every program planned after they are set, and a running job plans what it has not yet sent
again at the new values from a move boundary, moving (machine/override.py), as for the feed
override. In laser mode the rapids keep their speed: a move without a feed is what keeps the laser
off."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

from ..config import MachineConfig
from ..planner.feed_override import (
    Overrides,
    apply_overrides,
    check_rapid_percent,
    check_spindle_percent,
)
from ..planner.program import Program


class SpeedOverrides:
    """The rapid (25, 50, 100 %) and spindle (10–200 %) overrides wanted now; shared by a machine
    and the jobs it runs (`on_change` is called after each change: the machine wakes its job)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._rapid = 100
        self._spindle = 100
        self.on_change: Callable[[], None] | None = None

    @property
    def rapid(self) -> int:
        with self._lock:
            return self._rapid

    @property
    def spindle(self) -> int:
        with self._lock:
            return self._spindle

    def set_rapid(self, percent: int) -> int:
        """ValueError unless 25, 50 or 100."""
        with self._lock:
            self._rapid = check_rapid_percent(percent)
        self._changed()
        return percent

    def set_spindle(self, percent: int) -> int:
        """ValueError outside 10–200."""
        with self._lock:
            self._spindle = check_spindle_percent(percent)
        self._changed()
        return percent

    def at(self, feed: int) -> Overrides:
        """The three overrides wanted now, with the feed override `feed`."""
        with self._lock:
            return Overrides(feed, self._rapid, self._spindle)

    def apply(self, program: Program, config: MachineConfig, start: Sequence[int]) -> Program:
        """`program` (beginning at `start`, steps) with the rapids and spindle speeds scaled."""
        return apply_overrides(program, self.at(100), config, start)

    def _changed(self) -> None:
        if self.on_change is not None:
            self.on_change()
