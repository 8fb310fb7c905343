"""The dial-indicator measurement's moves and bookkeeping on one axis (backlash/dial.py has the
arithmetic): the preload toward the indicator, jogs back by single or larger steps, the move back
for a reading. The TUI's wizard runs these in a worker thread and shows what to do between them."""

from __future__ import annotations

from ..backlash.dial import (
    JOG_MM,
    DialPlan,
    DialResult,
    from_jog_back,
    from_reading,
    plan,
)
from .machine import Machine
from .raw_moves import RawMoves
from .units import step_direction

FEED = 2.0  # mm/s


class DialMeasurement:
    """One axis measured against a dial indicator on its `side` (+1: the axis's + side: preload +,
    back −)."""

    def __init__(
        self,
        machine: Machine,
        axis: str,
        side: int = 1,
        move_mm: float | None = None,
        jog_mm: float = JOG_MM,
        feed: float = FEED,
    ) -> None:
        config = machine.config
        self.machine = machine
        self.index = config.axis_names.index(axis)
        self.axis = config.axes[self.index]
        self.side = side
        self.plan: DialPlan = plan(self.axis, move_mm)
        self.jog_mm = jog_mm
        self.feed = feed
        self.count = 0  # steps jogged back since the preload
        self.last_jog = 0  # the last jog's steps

    def resize(self, move_mm: float) -> None:
        """A longer or shorter preload and move back (checked against the travel)."""
        self.plan = plan(self.axis, move_mm)

    def _move(self, toward: int) -> None:
        """`toward` motor steps toward the indicator (negative: away), to rest."""
        motor = step_direction(self.axis, self.side) * toward
        with self.machine.procedure("dial indicator"):
            RawMoves(self.machine, self.feed).move(self.index, motor)

    def preload(self) -> None:
        """Toward the indicator by the whole move: past the backlash, so the carriage presses it."""
        self._move(self.plan.move_steps)
        self.count = self.last_jog = 0

    def jog(self, large: bool = False) -> None:
        """Back by one motor step, or by the larger jog step."""
        steps = self.plan.jog_steps(self.jog_mm) if large else 1
        self._move(-steps)
        self.count += steps
        self.last_jog = steps

    @property
    def overdue(self) -> bool:
        """Jogged back past the preload and then a step: the needle must have moved by now, if the
        preload took the backlash up and the indicator touches the carriage."""
        return self.count > self.plan.move_steps + 1

    def move_back(self) -> None:
        """Back by the whole move, for a reading."""
        self._move(-self.plan.move_steps)

    def jogged(self) -> DialResult:
        """The needle moved on the last jog."""
        return from_jog_back(self.count, self.axis.steps_per_mm, self.plan, self.last_jog)

    def read(self, reading_mm: float) -> DialResult:
        """The indicator's reading after the move back."""
        return from_reading(
            self.plan.move_steps / self.axis.steps_per_mm,
            reading_mm,
            self.axis.steps_per_mm,
            self.plan,
        )


__all__ = ["FEED", "DialMeasurement"]
