"""The machine screen's rapid and spindle override keys (r, < >): the machine's overrides, for the
job running (planned again from its first move boundary not yet sent) and for every program planned
after. Mixed into MachineScreen, whose log and session they use."""

from __future__ import annotations

from typing import TYPE_CHECKING

from textual.screen import Screen

from ..planner.feed_override import MAX_PERCENT, MIN_PERCENT, STEP_PERCENT

if TYPE_CHECKING:
    from .session import Session

NEXT_RAPID = {100: 50, 50: 25, 25: 100}  # r: full, half, a quarter, full again


class OverrideKeys(Screen[None]):
    """The part of MachineScreen that sets the rapid and spindle overrides."""

    session: Session

    if TYPE_CHECKING:  # MachineScreen's own

        def log_line(self, text: str, error: bool = False) -> None: ...
        def refresh_panels(self) -> None: ...

    def action_rapid_override(self) -> None:
        """r: the rapids at 100 → 50 → 25 → 100 %."""
        machine = self.session.machine
        if machine is None:
            return
        percent = machine.set_rapid_override(NEXT_RAPID[machine.speed_overrides.rapid])
        self.log_line(f"rapid override {percent} %: {self._reach()}")
        self.refresh_panels()

    def action_spindle_override(self, delta: int) -> None:
        """< >: the spindle (or laser power) 10 % lower / higher, within 10–200 %."""
        machine = self.session.machine
        if machine is None:
            return
        now = machine.speed_overrides.spindle
        percent = min(MAX_PERCENT, max(MIN_PERCENT, now + delta * STEP_PERCENT))
        if percent == now:
            self.log_line(
                f"spindle override: {percent} % is the {'most' if delta > 0 else 'least'}",
                error=True,
            )
            return
        machine.set_spindle_override(percent)
        self.log_line(f"spindle override {percent} %: {self._reach()}")
        self.refresh_panels()

    def _reach(self) -> str:
        machine = self.session.machine
        running = machine is not None and machine.busy
        return "from the first move not yet sent" if running else "for what runs next"
