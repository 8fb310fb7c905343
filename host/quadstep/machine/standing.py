"""Where a machine stands: the board's step counts, the backlash's band, and the positions shown
without the take-ups (docs/BACKLASH.md) — at rest, while a program runs, at a latch — and whether it
is homed; all of it kept in the state file (state.py) at each change, with the board it belongs
to. Each Machine has one (machine.standing)."""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from ..backlash.band import BandRecord
from ..coordinates import WorkCoordinates
from ..link import Link, LinkError
from ..planner.segments import SegmentArrays
from ..protocol import CubicSegment, IdentifyReply, Segment, StatusReport
from .board_identity import board_mark
from .carry_over import CarriedOver, carry_over
from .errors import MachineError
from .motion import MotionEnd
from .state import StateFile, write_state
from .takeups import TakeUps


class Standing:
    """The step counts where the machine last stood still, its backlash's take-ups, whether it is
    homed, and the state file that keeps them with the work coordinates last stored."""

    def __init__(
        self, link: Link, takeups: TakeUps, state_file: Path | None, kept: StateFile
    ) -> None:
        self.link = link
        self.takeups = takeups
        self.state_file = state_file  # where the state is kept (None: in memory only)
        # the work coordinates as a work zero or a completed job left them: kept (a job running
        # changes the machine's as it goes)
        self.stored_coordinates = kept.coordinates
        self._lock = threading.Lock()
        self._state_lock = threading.Lock()  # one write of the state file at a time
        self._motor: tuple[int, ...] = ()  # the board's step counts where it last stood still
        self._ticks = 0  # the board's motion clock (at least) where it last stood still
        # Machine zero is known once homed; a hard limit or the abort button loses it (as GRBL's
        # alarm).
        self._homed = False
        self._position_lost = False

    @property
    def identity(self) -> IdentifyReply:
        assert self.link.identity is not None
        return self.link.identity

    @property
    def axis_count(self) -> int:
        """Configured axes (the firmware may drive more)."""
        return len(self.takeups.config.axes)

    @property
    def homed(self) -> bool:
        """Machine zero is known: found by homing since the board's last reset, not lost since."""
        return self._homed

    @property
    def position_lost(self) -> bool:
        """A hard limit or the abort button (or a reset) lost machine zero since it was found."""
        return self._position_lost

    def set_homed(self, homed: bool) -> None:
        """Homing ended: machine zero found on every axis that homes (or not)."""
        self._homed = homed
        self._position_lost = self._position_lost and not homed
        self.keep()

    def lose_position(self) -> None:
        """A hard limit or the abort button: machine zero is lost until the machine is homed."""
        self._homed, self._position_lost = False, True
        self.keep()

    @property
    def position(self) -> tuple[int, ...]:
        """Step position of every configured axis where the machine last stood still, exact, the
        backlash's take-ups excluded (the carriage's position: docs/BACKLASH.md)."""
        with self._lock:
            motor = self._motor
        return self.takeups.position(motor)

    @property
    def motor_position(self) -> tuple[int, ...]:
        """The board's own step counts there (take-ups included)."""
        with self._lock:
            return self._motor

    def live_position(self, status: StatusReport) -> tuple[int, ...]:
        """The position a status shows, take-ups excluded, also while a program runs."""
        return self.takeups.position(status.position[: self.axis_count], status.motion_ticks)

    def shown(self, motor: Sequence[int], tick: int) -> tuple[int, ...]:
        """A position the firmware reported at motion tick `tick` (a latch), take-ups excluded."""
        return self.takeups.position(motor[: self.axis_count], tick)

    def seen_at_rest(self, status: StatusReport) -> None:
        """A status read with nothing running: the counts and the clock where the machine stands."""
        with self._lock:
            self._motor = tuple(status.position[: self.axis_count])
            self._ticks = max(self._ticks, status.motion_ticks)

    def set_motors(self, motor: Sequence[int]) -> None:
        """The board's counts redefined (SET_POSITION), at rest."""
        with self._lock:
            self._motor = tuple(motor[: self.axis_count])
        self.keep()

    def takeup_stream(self, segments: Sequence[Segment]) -> list[Segment | CubicSegment]:
        """For a procedure that streams itself (homing, probing), at rest: `segments` with their
        take-ups. Until `rested()`, positions the firmware reports in between are shown by
        `live_position`/`shown`."""
        compensated = self.takeups.compensate(SegmentArrays.of(segments, self.identity.axis_count))
        status = self.link.status()
        self.takeups.begin(compensated, status.position[: self.axis_count], status.motion_ticks)
        return list(compensated.stream.segments())

    def raw_moved(self, before: Sequence[int], after: Sequence[int]) -> None:
        """A procedure's straight move without take-ups took the motors from `before` to `after` (at
        rest)."""
        self.takeups.moved_straight([a - b for a, b in zip(after, before)])
        with self._lock:
            self._motor = tuple(after[: self.axis_count])

    def rested(self, hold_tick: int | None = None) -> tuple[int, ...]:
        """A procedure's motion is at rest: after a hold that began at `hold_tick`, or (None) at its
        end."""
        status = self.link.status()
        self.rest(
            status.position,
            hold_tick if hold_tick is not None else status.motion_ticks,
            hold_tick is None,
        )
        return self.position

    def settle(self, end: MotionEnd, raw: Sequence[Segment] | None) -> MotionEnd:
        """In the program's thread, before its waiters wake: the exact rest position (motors), the
        band where the stop left it, and the end as everything above sees it (take-ups excluded)."""
        if not end.position:
            try:
                status = self.link.status()
            except LinkError:
                return end
            self.rest(status.position, status.motion_ticks, False)
            return end
        if raw is not None:
            self.takeups.moved_raw(raw, end.ended_by == "done")
            with self._lock:
                self._motor = tuple(end.position[: self.axis_count])
        else:
            tick = end.hold_tick
            if tick is None and end.ended_by != "done":
                try:
                    tick = self.link.status().motion_ticks
                except LinkError:
                    tick = None
            self.rest(end.position, tick, end.ended_by == "done")
        return replace(end, position=self.position)

    def rest(self, motor: Sequence[int], tick: int | None, done: bool) -> None:
        """The machine is at rest at `motor` (the board's counts), stopped at motion tick `tick`
        (None: not known), at the end of its program (`done`) or not: the band where it left it."""
        with self._lock:
            self._motor = tuple(motor[: self.axis_count])
            if tick is not None:
                self._ticks = max(self._ticks, tick)
        self.takeups.end(motor, tick, done)
        self.keep()

    def carry_over(self, kept: StateFile, status: StatusReport, new_board: bool) -> CarriedOver:
        """At connect, at rest: take what the state file keeps for this board; record the board."""
        carried = carry_over(kept, self.takeups.config, self.identity, status, new_board)
        self.stored_coordinates = carried.coordinates
        self.takeups.reset(carried.band)
        self._homed, self._position_lost = carried.homed, carried.position_lost
        self.keep(strict=True)
        return carried

    def store(self, coordinates: WorkCoordinates) -> None:
        """Work coordinates to keep (a work zero, what a completed job leaves)."""
        self.stored_coordinates = coordinates
        self.keep(strict=True)

    def keep(self, strict: bool = False) -> None:
        """Replace the state file with what the machine knows now. `strict`: a failure is a
        MachineError (a write the user asked for); otherwise it is let go (the state folder was
        found writable at connect)."""
        if self.state_file is None:
            return
        with self._lock:
            motor, ticks = self._motor, self._ticks
        band = self.takeups.band
        state = StateFile(
            coordinates=self.stored_coordinates,
            homed=self._homed,
            position_lost=self._position_lost,
            band=BandRecord.of(band, motor) if band.active else None,
            board=board_mark(self.identity, ticks, motor),
        )
        try:
            with self._state_lock:
                write_state(self.state_file, state)
        except OSError as exc:
            if strict:
                raise MachineError(
                    f"cannot write the machine's state to {self.state_file}: {exc.strerror or exc}"
                ) from None
