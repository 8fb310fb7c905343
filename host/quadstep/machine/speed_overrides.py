"""The rapid and spindle overrides of a machine (planner/feed_override.py has the arithmetic): they
apply to every program planned after they are set, and to a running job from its next leg (a
re-plan: after a feed hold, a pause, a probe or a feed override change). In laser mode the rapids
keep their speed: a move without a feed is what keeps the laser off."""

from __future__ import annotations

import threading
from collections.abc import Sequence

from ..config import MachineConfig
from ..planner.feed_override import (
    check_rapid_percent,
    check_spindle_percent,
    scale_rapids,
    scale_spindle,
)
from ..planner.program import Program


class SpeedOverrides:
    """The rapid (25, 50, 100 %) and spindle (10–200 %) overrides wanted now; shared by a machine
    and the jobs it runs."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._rapid = 100
        self._spindle = 100

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
        return percent

    def set_spindle(self, percent: int) -> int:
        """ValueError outside 10–200."""
        with self._lock:
            self._spindle = check_spindle_percent(percent)
        return percent

    def apply(self, program: Program, config: MachineConfig, start: Sequence[int]) -> Program:
        """`program` (beginning at `start`, steps) with the rapids and spindle speeds scaled."""
        with self._lock:
            rapid, spindle = self._rapid, self._spindle
        if not config.spindle.laser:
            speeds = [a.max_speed for a in config.axes]
            program = scale_rapids(program, rapid, speeds, config.to_mm(tuple(start)))
        return scale_spindle(program, spindle)
