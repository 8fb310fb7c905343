"""GRBL's override bytes (0x90–0x9D) on the machine: the feed override (10–200 %) onto the running
batch at once, through the job's own feed override (machine/override.py: the rest re-planned from a
move boundary, moving), and onto every batch planned after; the rapid (100, 50, 25 %) and spindle
(10–200 %) overrides likewise, through the machine's (machine/speed_overrides.py).
The status report's `Ov:` says what is in force. The coolant toggles (0xA0 flood, 0xA1 mist) and
the spindle stop (0x9E: during a feed hold only, the spindle off until toggled again or resumed)
are here too: GRBL's accessory overrides."""

from __future__ import annotations

from dataclasses import replace

from ..link import LinkError
from ..machine import Machine, MachineError
from ..planner.feed_override import clamped
from ..planner.program import OutputState
from .executor import Executor

FEED_RESET, FEED_UP_10, FEED_DOWN_10, FEED_UP_1, FEED_DOWN_1 = 0x90, 0x91, 0x92, 0x93, 0x94
RAPID = {0x95: 100, 0x96: 50, 0x97: 25}
SPINDLE_RESET, SPINDLE_UP_10, SPINDLE_DOWN_10, SPINDLE_UP_1, SPINDLE_DOWN_1 = (
    0x99,
    0x9A,
    0x9B,
    0x9C,
    0x9D,
)
SPINDLE_STOP = 0x9E
FLOOD_TOGGLE, MIST_TOGGLE = 0xA0, 0xA1
COOLANT_TOGGLES = frozenset({FLOOD_TOGGLE, MIST_TOGGLE})
OVERRIDE_BYTES = frozenset(range(0x90, 0x98)) | frozenset(range(0x99, 0x9E))
_STEPS = {1: 10, 2: -10, 3: 1, 4: -1}  # the offset of a +/- byte from its reset byte


def stepped(percent: int, byte: int, reset: int) -> int:
    """The percentage after `byte` (reset, ±10, ±1), kept within 10–200 %."""
    if byte == reset:
        return 100
    return clamped(percent + _STEPS[byte - reset])


def toggled(state: OutputState, byte: int) -> OutputState:
    """The outputs with flood (0xA0) or mist (0xA1) the other way."""
    if byte == FLOOD_TOGGLE:
        return replace(state, flood=not state.flood)
    return replace(state, mist=not state.mist)


class Overrides:
    """The front door's overrides on `machine`, applied through `executor`."""

    def __init__(self, machine: Machine, executor: Executor) -> None:
        self.machine = machine
        self.executor = executor
        self.changed = True  # the next status report carries Ov:
        self.spindle_stopped = False  # 0x9E during the feed hold under way

    @property
    def values(self) -> tuple[int, int, int]:
        speeds = self.machine.speed_overrides
        return self.executor.feed_override, speeds.rapid, speeds.spindle

    def realtime(self, byte: int) -> None:
        """One override byte (in OVERRIDE_BYTES)."""
        if byte in RAPID:
            self.machine.set_rapid_override(RAPID[byte])
        elif byte >= SPINDLE_RESET:
            spindle = self.machine.speed_overrides.spindle
            self.machine.set_spindle_override(stepped(spindle, byte, SPINDLE_RESET))
        else:
            self._feed(stepped(self.executor.feed_override, byte, FEED_RESET))
        self.changed = True

    def _feed(self, percent: int) -> None:
        self.executor.feed_override = percent
        job = self.executor.running_job()
        if job is None:
            return
        try:
            job.set_feed_override(percent)
        except MachineError:
            pass  # a jerk-limited batch keeps its feeds; the next one takes the new override

    def spindle_stop(self) -> None:
        """0x9E: during a feed hold, the spindle off, or on again; ignored otherwise (as GRBL
        does)."""
        job = self.executor.running_job()
        if job is None or not job.held:
            return
        try:
            if job.stop_spindle(not self.spindle_stopped):
                self.spindle_stopped = not self.spindle_stopped
        except LinkError:
            pass  # the link's own fault is reported where it is used next

    def resumed(self) -> None:
        """Cycle start: the job goes on with the spindle it had (planned again from the hold)."""
        self.spindle_stopped = False

    def reset(self) -> None:
        """A soft reset: every override back to 100 %, as GRBL does."""
        self.executor.feed_override = 100
        self.machine.set_rapid_override(100)
        self.machine.set_spindle_override(100)
        self.spindle_stopped = False
        self.changed = True
