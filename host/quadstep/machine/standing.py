"""Where a machine stands: the board's step counts, the backlash's band, and the positions shown
without the take-ups (docs/BACKLASH.md) — at rest, while a program runs, at a latch — and whether it
is homed; all of it kept in the state file (state.py) at each change, with the board it belongs
to."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from ..backlash.band import BandRecord
from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..link import Link, LinkError
from ..planner.plan import Plan
from ..planner.program import ProbeMove
from ..planner.segments import SegmentArrays
from ..protocol import CubicSegment, IdentifyReply, Segment, SetPosition, StatusReport
from .board_identity import board_mark
from .carry_over import carry_over
from .errors import MachineError
from .motion import MotionEnd
from .probing import probe as run_probe
from .state import StateFile, write_state
from .takeups import StreamPlan, TakeUps


class Standing:
    """The part of a Machine that knows where it stands (a mixin: the Machine makes the fields)."""

    link: Link
    takeups: TakeUps
    state_file: Path | None
    _lock: threading.Lock
    _motor: tuple[int, ...]
    _ticks: int  # the board's motion clock (at least) where it last stood still
    _homed: bool
    _position_lost: bool
    _state_lock: threading.Lock  # one write of the state file at a time
    new_board: bool  # cannot be the board the state file was written for (an emulator started anew)
    notice: str | None  # what opening the machine found of the kept state, for the user
    coordinates: WorkCoordinates  # in force (a job running changes them as it goes)
    _stored_coordinates: WorkCoordinates  # as a work zero or a completed job left them: kept
    adopt_coordinates: Callable[[WorkCoordinates], None]
    _refuse_if_busy: Callable[[str], None]
    config: MachineConfig
    decels: tuple[int, ...]  # HOLD decelerations per axis

    if TYPE_CHECKING:  # the Machine's properties and methods (it probes: probing.ProbingMachine)

        @property
        def identity(self) -> IdentifyReply: ...

        @property
        def position_mm(self) -> tuple[float, ...]: ...

        def procedure(self, name: str) -> AbstractContextManager[object]: ...

        def sync(self) -> tuple[int, ...]: ...

        @property
        def axis_count(self) -> int: ...

        @property
        def program(self) -> object | None: ...  # the program running (machine.Running)

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
        self._keep_state()

    def lose_position(self) -> None:
        """A hard limit or the abort button: machine zero is lost until the machine is homed."""
        self._homed, self._position_lost = False, True
        self._keep_state()

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

    def set_position(self, steps: dict[int, int], within: object | None = None) -> tuple[int, ...]:
        """Redefine the position of some axes (SET_POSITION): only at rest (or by the procedure
        `within`, which holds the machine). Machine coordinates move with it, so this is for homing
        and tools; work coordinates are the user's zero."""
        if within is None or self.program is not within:
            self._refuse_if_busy("set the position")
        offsets = [m - p for m, p in zip(self.motor_position, self.position)]
        self.link.send(
            SetPosition(
                positions={a: s + (offsets[a] if a < len(offsets) else 0) for a, s in steps.items()}
            )
        )
        self.link.drain()
        status = self.link.status()
        with self._lock:
            self._motor = tuple(status.position[: self.axis_count])
        self._keep_state()
        return self.position

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

    def shown(self, motor: Sequence[int], tick: int) -> tuple[int, ...]:
        """A position the firmware reported at motion tick `tick` (a latch), take-ups excluded."""
        return self.takeups.position(motor[: self.axis_count], tick)

    def rested(self, hold_tick: int | None = None) -> tuple[int, ...]:
        """A procedure's motion is at rest: after a hold that began at `hold_tick`, or (None) at its
        end."""
        status = self.link.status()
        self._rest(
            status.position,
            hold_tick if hold_tick is not None else status.motion_ticks,
            hold_tick is None,
        )
        return self.position

    def _settle(self, end: MotionEnd, raw: Sequence[Segment] | None) -> MotionEnd:
        """In the program's thread, before its waiters wake: the exact rest position (motors), the
        band where the stop left it, and the end as everything above sees it (take-ups excluded)."""
        if not end.position:
            try:
                status = self.link.status()
            except LinkError:
                return end
            self._rest(status.position, status.motion_ticks, False)
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
            self._rest(end.position, tick, end.ended_by == "done")
        return replace(end, position=self.position)

    def _rest(self, motor: Sequence[int], tick: int | None, done: bool) -> None:
        with self._lock:
            self._motor = tuple(motor[: self.axis_count])
            if tick is not None:
                self._ticks = max(self._ticks, tick)
        self.takeups.end(motor, tick, done)
        self._keep_state()

    def _carry_over(self, kept: StateFile, status: StatusReport) -> None:
        """At connect, at rest: take what the state file keeps for this board; record the board."""
        carried = carry_over(kept, self.takeups.config, self.identity, status, self.new_board)
        self.coordinates = self._stored_coordinates = carried.coordinates
        self.takeups.reset(carried.band)
        self._homed, self._position_lost = carried.homed, carried.position_lost
        self.notice = carried.notice
        self._keep_state(strict=True)

    def _keep_state(self, strict: bool = False) -> None:
        """Replace the state file with what the machine knows now. `strict`: a failure is a
        MachineError (a write the user asked for); otherwise it is let go (the state folder was
        found writable at connect)."""
        if self.state_file is None:
            return
        with self._lock:
            motor, ticks = self._motor, self._ticks
        band = self.takeups.band
        state = StateFile(
            coordinates=self._stored_coordinates,
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


class Restream(Protocol):
    """What the machine does for a job going on after a feed hold: the band where the hold left it
    and the position at rest (take-ups excluded), then the rest of the job with its take-ups."""

    def held(self, end: MotionEnd) -> tuple[int, ...]: ...

    def stream(self, plan: Plan) -> StreamPlan: ...

    def restream(self, plan: Plan, running: StreamPlan) -> StreamPlan: ...

    def swap(self, streamed: StreamPlan) -> None: ...

    def at_rest(self) -> tuple[int, ...]: ...

    def position(self) -> tuple[int, ...]: ...

    def coordinates(self) -> WorkCoordinates: ...

    def probe(self, probe: ProbeMove) -> tuple[float, ...]: ...

    def adopt(self, coordinates: WorkCoordinates) -> None: ...


class _Restream:
    """A job of this machine goes on after a feed hold (machine/job.py, Restream)."""

    def __init__(self, machine: Standing) -> None:
        self.machine = machine

    def held(self, end: MotionEnd) -> tuple[int, ...]:
        status = self.machine.link.status()
        self.machine._rest(status.position, end.hold_tick, False)
        return self.machine.position

    def at_rest(self) -> tuple[int, ...]:
        """Where a job stands at its pause, the band as its take-ups left it there."""
        status = self.machine.link.status()
        self.machine._rest(status.position, status.motion_ticks, False)
        return self.machine.position

    def position(self) -> tuple[int, ...]:
        return self.machine.position

    def coordinates(self) -> WorkCoordinates:
        return self.machine.coordinates.model_copy(deep=True)

    def probe(self, probe: ProbeMove) -> tuple[float, ...]:
        """A job's G38.x, as `quadstep probe` runs it; the machine position where it rests (mm)."""
        run_probe(self.machine, probe.code, probe.target, probe.feed)
        return self.machine.position_mm

    def adopt(self, coordinates: WorkCoordinates) -> None:
        """In memory only: the state file keeps what a work zero or a completed job sets."""
        self.machine.coordinates = coordinates

    def restream(self, plan: Plan, running: StreamPlan) -> StreamPlan:
        """`plan`, which begins as `running` did, with its take-ups from the same band: what follows
        the part of them that is the same replaces the running program's (a feed override)."""
        band = running.compensated.band_start
        compensated = self.machine.takeups.compensate(plan.segments, plan.pauses, band)
        return StreamPlan(plan.config, compensated.stream, compensated.pauses, compensated, plan)

    def swap(self, streamed: StreamPlan) -> None:
        self.machine.takeups.swap(streamed.compensated)

    def stream(self, plan: Plan) -> StreamPlan:
        compensated = self.machine.takeups.compensate(plan.segments, plan.pauses)
        status = self.machine.link.status()
        self.machine.takeups.begin(
            compensated, status.position[: self.machine.axis_count], status.motion_ticks
        )
        return StreamPlan(plan.config, compensated.stream, compensated.pauses, compensated, plan)
