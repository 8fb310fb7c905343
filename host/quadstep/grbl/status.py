"""The `?` status report: GRBL's state name, the position (machine or work, as $10 says), the
buffers' room where $10 asks for it, feed and speed, the active inputs, and the work offset every
WCO_EVERY reports (and whenever it changed), as GRBL sends it now and then to save bandwidth."""

from __future__ import annotations

import math
from bisect import bisect_left
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Protocol

from ..config import MachineConfig
from ..link import LinkError
from ..machine import JobRun, Machine
from ..machine.job_legs import base_plan
from ..planner.program import LinearMove, OutputState
from .executor import Executor
from .overrides import Overrides
from .pins import pin_letters
from .probe import ProbeHold
from .protocol import StatusFields, status_report
from .reader import Reader

WCO_EVERY = 10
# Bf: GRBL's planner blocks and receive buffer bytes free, as an Uno's GRBL has them ($I's OPT:).
# The host takes every byte as it comes; the blocks free fall as lines wait to be planned.
PLANNER_BLOCKS = 15
RX_BUFFER_BYTES = 128
MPOS, BUFFER_STATE = 1, 2  # $10's bits


@dataclass
class StatusMask:
    """$10, what a report carries (bit 0 set: MPos, clear: WPos; bit 1: Bf:). Shared by the
    sessions of one `quadstep grbl` for as long as it runs (GRBL keeps it in EEPROM)."""

    value: int = MPOS


class SessionView(Protocol):
    """What a report reads of the session."""

    machine: Machine
    reader: Reader
    executor: Executor
    overrides: Overrides
    alarm: bool
    check_mode: bool
    homing: bool
    probing: bool
    probe_hold: ProbeHold
    sleeping: bool
    inputs_active: int  # the board's inputs active now (an input mask)
    status_mask: StatusMask


def accessories(outputs: OutputState) -> str:
    """GRBL's A: letters for the outputs as the lines read so far leave them."""
    spindle = {3: "S", 4: "C"}.get(outputs.spindle, "")
    return spindle + ("F" if outputs.flood else "") + ("M" if outputs.mist else "")


def rapid_speed(config: MachineConfig, start: Sequence[float], end: Sequence[float]) -> float:
    """A rapid's speed along its path (mm/s): the fastest at which no axis passes its top speed."""
    length = math.dist(start, end)
    limits = [
        axis.max_speed * length / abs(b - a)
        for axis, a, b in zip(config.axes, start, end)
        if b != a
    ]
    return min(limits, default=0.0)


def running_feed(job: JobRun, config: MachineConfig) -> tuple[float, bool] | None:
    """The speed (mm/s) of the line the job runs now, not of the last line read (a sender is many
    lines ahead), and whether it is a rapid's; None when it moves nothing."""
    program, line = job.program, job.progress.line
    if program is None:
        return None
    items = program.items
    first = bisect_left(items, line, key=lambda item: item.line)
    for k in range(first, len(items)):
        item = items[k]
        if item.line != line:
            break
        if not isinstance(item, LinearMove):
            continue
        if item.feed is not None:
            return item.feed, False
        before = [i for i in items[max(0, k - 8) : k] if isinstance(i, LinearMove)]
        start = before[-1].target if before else config.to_mm(base_plan(job.plan).start)
        return rapid_speed(config, start, item.target), True
    return None


class StatusBuilder:
    def __init__(self, session: SessionView) -> None:
        self.session = session
        self._count = 0
        self._last_wco: tuple[float, ...] | None = None

    def state(self) -> str:
        session = self.session
        if session.sleeping:
            return "Sleep"
        if session.homing:
            return "Home"
        if session.alarm:
            return "Alarm"
        if session.probing:
            return session.probe_hold.state or "Run"
        moving = session.executor.grbl_state()
        if moving is not None:
            return moving
        return "Check" if session.check_mode else "Idle"

    def position(self) -> tuple[float, ...]:
        """Machine mm: where it stands, read from the board while a program runs."""
        machine = self.session.machine
        if machine.busy:
            try:
                return machine.config.to_mm(machine.standing.live_position(machine.status()))
            except LinkError:
                pass
        return machine.position_mm

    def _feed(self, read: float | None, overrides: tuple[int, int, int]) -> float:
        """FS's feed, mm/min: the running line's, at the overrides (a jog's at its own: the
        overrides do not apply to jogs, executor.py); the last line read's while none runs yet."""
        running = self.session.executor.running()
        if running is None:
            return (read or 0.0) * 60 * overrides[0] / 100
        feed = running_feed(running.run, self.session.machine.config)
        if feed is None:
            return 0.0
        speed, rapid = feed
        percent = 100 if running.jog else overrides[1 if rapid else 0]
        return speed * 60 * percent / 100

    def report(self) -> str:
        session = self.session
        state = self.state()
        interpreter = session.reader.interpreter
        coordinates = interpreter.coords
        wco = tuple(coordinates.offset(a) for a in session.machine.config.axis_names)
        running = state in ("Run", "Jog", "Hold:1")
        ov = session.overrides.values
        feed = self._feed(interpreter.feed, ov) if running else 0.0
        show_wco = self._count % WCO_EVERY == 0 or wco != self._last_wco
        self._count += 1
        if show_wco:
            self._last_wco = wco
        show_ov = session.overrides.changed or self._count % WCO_EVERY == 2
        session.overrides.changed = False
        mask = session.status_mask.value
        position = self.position()
        if not mask & MPOS:  # GRBL's WPos = MPos - WCO
            position = tuple(p - o for p, o in zip(position, wco))
        waiting = session.executor.lines_waiting()
        fields = StatusFields(
            state,
            position,
            feed,
            interpreter.outputs.speed,
            wco if show_wco else None,
            accessories(
                replace(interpreter.outputs, spindle=5)  # 0x9E: stopped during the hold
                if session.overrides.spindle_stopped
                else interpreter.outputs
            ),
            ov if show_ov else None,
            work=not mask & MPOS,
            buffer=(max(0, PLANNER_BLOCKS - waiting), RX_BUFFER_BYTES)
            if mask & BUFFER_STATE
            else None,
            pins=pin_letters(session.inputs_active, session.machine.config.axis_names),
        )
        return status_report(fields)
