"""One connected machine: its link, its configuration, where it stands, and the one program it runs.

A Machine is made on a connected Link (or by open_machine, which opens the
port or starts the emulator too). Making it checks, once, that the firmware
can run what the configuration plans, and reads the exact step position. It
then runs one program at a time — a job, a jog, raw segments — and stops it.

The stop rule: `hold()` is the user's stop, a controlled deceleration to
rest (HOLD) after which the exact position is known; `emergency_stop()` is
the immediate STOP, for the emergency key only. Positions are the board's
step counts, exact; mm are derived from them through the configuration.
Work coordinates (G54–G59, G92, G28/G30: quadstep.coordinates), the backlash's
band and whether the machine is homed are kept in the state file (state.py)
when the machine has one, for the same boot of the board (carry_over.py); the
soft limits are always machine coordinates.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

from ..backlash.compensate import Compensated
from ..config import DEFAULT_CONFIG_NAME, MachineConfig, default_config
from ..coordinates import WorkCoordinates
from ..default_machine import default_machine
from ..link import Link, LinkError, LinkStats, hold
from ..planner.feed_override import Overrides, apply_overrides
from ..planner.outputs import output_message
from ..planner.plan import Plan, plan_program
from ..planner.program import OutputState, Program
from ..planner.raster_gcode import plan_with_rasters
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from ..port_process import PortProcess
from ..protocol import (
    Alarm,
    AlarmCode,
    Capability,
    IdentifyReply,
    Report,
    Segment,
    SetPosition,
    State,
    StatusReport,
    Watchdog,
)
from .agreement import check_agreement
from .errors import MachineError
from .inputs import config_message
from .job import JobRun
from .journal import Journal
from .motion import Motion, MotionEnd, bring_to_rest
from .open_end import FLOOR_S
from .restream import MachineRestream
from .speed_overrides import SpeedOverrides
from .standing import Standing
from .state import StateFile, read_state
from .state_lock import StateLock
from .takeups import StreamPlan, TakeUps
from .units import hold_decels


def fallback_config(identity: IdentifyReply) -> MachineConfig:
    """Without a configuration: the default machine where the firmware is the one it describes (the
    emulator started for it, an Uno at its 32 kHz), else a generic one from what the firmware
    says."""
    default = default_machine()
    if identity.tick_hz == default.tick_hz and identity.axis_count == len(default.axes):
        return default
    return default_config(identity.tick_hz, identity.axis_count)


class Procedure:
    """A routine that drives the link itself (homing, probing) while it holds the machine; halt() is
    the user's stop for it: a HOLD, which ends whatever it streams (it then raises Stopped)."""

    def __init__(self, machine: Machine, name: str) -> None:
        self.machine = machine
        self.name = name
        self.halted: str | None = None

    def halt(self, reason: str = "stop") -> MotionEnd | None:
        self.halted = reason
        hold(self.machine.link, self.machine.decels)
        return None

    def __enter__(self) -> Procedure:
        self.machine._claim(self)
        return self

    def __exit__(self, *exc: object) -> None:
        self.machine._release(self)


Running = Motion | JobRun | Procedure  # what the machine runs, one at a time
Started = TypeVar("Started", Motion, JobRun)  # what _begin() starts (a Procedure claims itself)


class Machine:
    """The machine behind `link`, described by `config` (None: a generic one, see
    config.default_config)."""

    def __init__(
        self,
        link: Link,
        config: MachineConfig | None = None,
        *,
        source: str = "the configuration",
        emulator: PortProcess | None = None,
        state_file: Path | None = None,
        state_lock: StateLock | None = None,
    ) -> None:
        identity = link.identity
        if identity is None:
            raise MachineError("the link is not connected")
        self.link = link
        self.config_given = config is not None
        self.config = config if config is not None else fallback_config(identity)
        check_agreement(
            identity, self.config, source if config is not None else DEFAULT_CONFIG_NAME
        )
        self.emulator = emulator  # an emulator this machine started, stopped by close()
        self.decels = hold_decels(self.config)  # HOLD decelerations: each axis's max_accel
        self.state_file = state_file  # where the state is kept (None: in memory only)
        self.state_lock = state_lock  # held while open (open_machine takes it), released by close()
        kept = read_state(state_file) if state_file is not None else StateFile()
        self.coordinates = kept.coordinates  # in force (a job running changes them as it goes)
        self.new_board = emulator is not None  # cannot be the board the state file was written for
        self.notice: str | None = None  # what opening the machine found of the kept state
        # the backlash: take-ups in every program, positions without them
        self.takeups = TakeUps(self.config)
        self.standing = Standing(link, self.takeups, state_file, kept)
        self.speed_overrides = SpeedOverrides()  # rapid and spindle, for the programs planned next
        self.speed_overrides.on_change = self._overrides_changed  # and for the job running
        self._lock = threading.Lock()
        self._running: Running | None = None
        self._waiting: JobRun | None = None  # a job waiting at a pause while another program runs
        link.on_report(self._watch_alarms)
        # left dry by a host gone (a killed job): take it up
        if link.status().state == State.STARVED:
            bring_to_rest(link, self.decels)
        if identity.capabilities & Capability.LIMIT_INPUTS and link.status().state in (
            State.IDLE,
            State.ALARM,
        ):
            link.send(config_message(self.config, identity.axis_count))
            link.drain(timeout=5)
        # the link keeps it fed while anything moves
        if identity.capabilities & Capability.CONTROLLED_STOPS:
            link.request(Watchdog(timeout_ms=round(self.config.host_timeout * 1000)), StatusReport)
        carried = self.standing.carry_over(kept, self.status(), self.new_board)
        self.coordinates, self.notice = carried.coordinates, carried.notice

    # --- what the machine is and where it stands ----------------------------------------------

    @property
    def identity(self) -> IdentifyReply:
        return self.standing.identity

    @property
    def axis_count(self) -> int:
        """Configured axes (the firmware may drive more)."""
        return self.standing.axis_count

    @property
    def position(self) -> tuple[int, ...]:
        """Step position of every configured axis where the machine last stood still, exact, the
        backlash's take-ups excluded (standing.py)."""
        return self.standing.position

    @property
    def motor_position(self) -> tuple[int, ...]:
        """The board's own step counts there (take-ups included)."""
        return self.standing.motor_position

    @property
    def homed(self) -> bool:
        """Machine zero is known: found by homing since the board's last reset, not lost since."""
        return self.standing.homed

    @property
    def position_lost(self) -> bool:
        """A hard limit or the abort button (or a reset) lost machine zero since it was found."""
        return self.standing.position_lost

    @property
    def position_mm(self) -> tuple[float, ...]:
        return self.config.to_mm(self.position)

    @property
    def work_position(self) -> tuple[float, ...]:
        """Where the machine stands in the active work coordinates (mm)."""
        return self.coordinates.to_work(self.config.axis_names, self.position_mm)

    def set_work_zero(self, axes: Sequence[int]) -> tuple[float, ...]:
        """Make the current position 0 in the active work coordinates on `axes` (G10 L20 P0), and
        keep it."""
        self._refuse_if_busy("set a work zero")
        self.sync()
        coordinates = self.coordinates.model_copy(deep=True)
        machine = self.position_mm
        for axis in axes:
            coordinates.set_position(0, self.config.axes[axis].name, machine[axis], 0.0)
        self.adopt_coordinates(coordinates)
        return self.work_position

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
        self.standing.set_motors(self.link.status().position)
        return self.position

    def adopt_coordinates(self, coordinates: WorkCoordinates) -> None:
        """Take the work coordinates a job left (or any others) and keep them in the state file."""
        self.coordinates = coordinates
        self.standing.store(coordinates)

    @property
    def stats(self) -> LinkStats:
        """What the link did: frames, retransmissions, errors."""
        return self.link.stats

    @property
    def busy(self) -> bool:
        """A program runs (and the position changes)."""
        with self._lock:
            return self._running is not None

    @property
    def program(self) -> Running | None:
        """The program running, if one is."""
        with self._lock:
            return self._running

    def status(self) -> StatusReport:
        """The firmware's status; at rest, the position is taken from it."""
        status = self.link.status()
        if status.state == State.IDLE and status.queue_fill == 0:
            with self._lock:
                if self._running is None:
                    self.standing.seen_at_rest(status)
        return status

    def sync(self) -> tuple[int, ...]:
        """Read where the machine stands (at rest) and return it."""
        self.status()
        return self.position

    # --- programs ---------------------------------------------------------------------------------

    def move(
        self, segments: SegmentArrays | Stream, *, lookahead_ticks: int | None = None
    ) -> Motion:
        """Start streaming planned segments now, the backlash taken up in them; wait() on the
        Motion."""
        compensated = self.takeups.compensate(segments)
        motion = Motion(self.link, compensated.stream, self.decels, lookahead_ticks=lookahead_ticks)
        return self._begin(motion, compensated).start()

    def run_job(
        self,
        plan: Plan,
        program: Program | None = None,
        label: str = "line",
        feed_override: int = 100,
        journal: Journal | None = None,
        open_end: bool = False,
        leaves: WorkCoordinates | None = None,
        overridden: bool = False,
        open_floor_s: float = FLOOR_S,
    ) -> JobRun:
        """Start a planned job now, the backlash taken up in it (pauses wait for JobRun.resume()).
        With the `program` it was planned from, a feed hold (JobRun.feed_hold, the board's button)
        keeps the rest of the job for resume(), and JobRun.set_feed_override changes its feeds on
        the way (the plan is planned at `feed_override` %, the program as written); a `journal`
        keeps each leg of it for `run --resume`; an `open_end` job takes more lines as it runs
        (JobRun.extend), and keeps the end of what it has back from the board until the board holds
        less than `open_floor_s` of motion before it (open_end.py); `leaves` are the work
        coordinates its G10, G92, G54…G59 and M2/M30 leave, the machine's once the job completes.
        The plan is planned again at the rapid and spindle overrides unless it is `overridden`
        (planned at them already); changes to them reach the job on its way."""
        if plan.outputs and not self.identity.capabilities & Capability.OUTPUTS:
            raise MachineError(
                "the job sets the spindle, laser or coolant (M3/M4/M5, M7/M8/M9) and this firmware "
                "has no outputs; --skip-unsupported runs it without them"
            )
        speeds = self.speed_overrides.at(feed_override)
        if program is not None and not overridden and speeds != Overrides(feed_override):
            scaled = apply_overrides(program, speeds, plan.config, plan.start)
            plan = plan_program(scaled, plan.config, plan.start, label)
        if (
            program is not None
            and speeds == Overrides()
            and self.identity.capabilities & (Capability.RASTER)
        ):  # laser rasters in the program go out as RASTER lines
            plan = plan_with_rasters(program, plan.config, plan.start, label) or plan
        compensated = self.takeups.compensate(plan.segments, plan.pauses)
        streamed = StreamPlan(
            plan.config, compensated.stream, compensated.pauses, compensated, plan
        )
        job = JobRun(
            self.link,
            streamed,
            self.decels,
            program=program,
            label=label,
            feed_override=feed_override,
            speed_overrides=self.speed_overrides,
            restream=MachineRestream(self),
            busy_elsewhere=lambda: self._waiting is job,
            journal=journal,
            open_end=open_end,
            open_floor_s=open_floor_s,
        )
        return self._begin(job, compensated, leaves=leaves).start()

    def set_rapid_override(self, percent: int) -> int:
        """The rapids at 25, 50 or 100 % (ValueError else): of the job running, from its first move
        boundary not yet sent, and of every program planned from now on; see overridden()."""
        return self.speed_overrides.set_rapid(percent)

    def set_spindle_override(self, percent: int) -> int:
        """Every S at 10–200 % (ValueError outside): of the job running, from its first move
        boundary not yet sent, and of every program planned from now on."""
        return self.speed_overrides.set_spindle(percent)

    def overridden(self, program: Program) -> Program:
        """`program`, to be planned from where the machine stands, with the rapid and spindle
        overrides."""
        return self.speed_overrides.apply(program, self.config, self.position)

    def _overrides_changed(self) -> None:
        with self._lock:
            running = self._running
        if isinstance(running, JobRun):
            running.overrides_changed()

    def set_outputs(self, state: OutputState) -> None:
        """At rest: the spindle, laser and coolant as `state` says, now (a sender's coolant
        toggle)."""
        self._refuse_if_busy("set the outputs")
        if not self.identity.capabilities & Capability.OUTPUTS:
            raise MachineError("this firmware has no outputs (spindle, laser, coolant)")
        self.link.send(output_message(state, self.config))
        self.link.drain(timeout=2)

    def send_segments(self, segments: Sequence[Segment]) -> Motion:
        """Start streaming raw segments (every firmware axis) now, as they are (no take-ups
        added)."""
        arrays = SegmentArrays.of(segments, self.identity.axis_count)
        motion = Motion(self.link, arrays, self.decels)
        return self._begin(motion, raw=segments).start()

    def hold(self, reason: str = "stop") -> MotionEnd | None:
        """The user's stop: bring the running program to rest with HOLD; returns how it ended, with
        the exact rest position (None when nothing ran)."""
        program = self.program
        return program.halt(reason) if program is not None else None

    def emergency_stop(self) -> StatusReport:
        """Immediate STOP, no deceleration (positions stay exact); also clears an alarm."""
        status = self.link.stop()
        self.standing.rest(status.position, status.motion_ticks, False)
        return status

    # --- reports from the firmware ----------------------------------------------------------------

    def on_report(self, callback: Callable[[Report], None]) -> Callable[[], None]:
        """Call `callback` (in the reader thread; keep it short) for every ALARM, ERROR, EVENT and
        SPACE ack; returns the function that unregisters it."""
        return self.link.on_report(callback)

    def report_count(self, cls: type[Report]) -> int:
        return self.link.report_count(cls)

    def wait_report(
        self, cls: type[Report], after: int, timeout: float | None = None
    ) -> Report | None:
        """Until report number `after` + 1 of class `cls` arrives (see report_count); None on
        timeout."""
        return self.link.wait_report(cls, after, self.link.generation, timeout)

    # --- closing ----------------------------------------------------------------------------------

    def close(self, bring_to_rest: bool = True) -> None:
        """Bring a running program to rest (unless told not to: a link known to be lost), close the
        link, stop an emulator this machine started."""
        try:
            if bring_to_rest:
                self.hold("quit")
        except LinkError:
            pass  # the link is gone already
        finally:
            try:
                if bring_to_rest:  # the board's clock and counts as left, for the next command
                    self.status()
            except LinkError:
                pass
            self.standing.keep()
            self.link.close()
            if self.emulator is not None:
                self.emulator.stop()
            if self.state_lock is not None:
                self.state_lock.release()

    def __enter__(self) -> Machine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- internals --------------------------------------------------------------------------------

    def _refuse_if_busy(self, what: str) -> None:
        with self._lock:
            running = self._running
        if running is not None and not (isinstance(running, JobRun) and running.gives_way):
            raise MachineError(f"cannot {what}: a program is running (stop it first)")

    def _take(self, program: Running) -> None:
        """Under the lock: `program` runs now. A job waiting at a pause gives way to it, and runs
        again after."""
        running = self._running
        if running is not None:
            if (
                not isinstance(running, JobRun)
                or not running.gives_way
                or self._waiting is not None
            ):
                raise MachineError("a program is running already: one at a time (stop it first)")
            self._waiting = running
        self._running = program

    def _free(self, program: Running) -> None:
        """Under the lock: `program` ended; a job that gave way to it is the one running again."""
        if self._running is program:
            self._running, self._waiting = self._waiting, None

    def procedure(self, name: str) -> Procedure:
        """Hold the machine for a routine that drives the link itself (a context manager)."""
        return Procedure(self, name)

    def _watch_alarms(self, report: Report) -> None:
        if isinstance(report, Alarm) and report.code in (AlarmCode.HARD_LIMIT, AlarmCode.E_STOP):
            self.standing.lose_position()

    def _claim(self, program: Running) -> None:
        self._interrupt_waiting()
        with self._lock:
            self._take(program)

    def _release(self, program: Running) -> None:
        with self._lock:
            self._free(program)
            waiting = self._running is not None
        if not waiting:
            self.sync()

    def _interrupt_waiting(self) -> None:
        """Before another program runs while a job waits at its pause: the machine stands where the
        job does."""
        with self._lock:
            running = self._running
        if isinstance(running, JobRun) and running.gives_way:
            running.interrupt()

    def _begin(
        self,
        program: Started,
        compensated: Compensated | None = None,
        raw: Sequence[Segment] | None = None,
        leaves: WorkCoordinates | None = None,
    ) -> Started:
        if self.config.homing_required and not self.homed:
            raise MachineError(
                "homing_required = true in the configuration: home the machine first "
                "(quadstep home, or h in the TUI)"
            )
        self._interrupt_waiting()
        with self._lock:
            self._take(program)
        if compensated is not None:
            # at rest: where the stream begins, in steps and motion ticks
            status = self.link.status()
            self.takeups.begin(compensated, status.position[: self.axis_count], status.motion_ticks)
        program.settle = lambda end: self.standing.settle(end, raw)
        program.on_end = lambda end: self._ended(program, end, leaves)
        return program

    def _ended(self, program: Running, end: MotionEnd, leaves: WorkCoordinates | None) -> None:
        """In the program's thread, before its waiters wake (after _settle): the machine is free
        again, with the work coordinates a completed program leaves."""
        if leaves is not None and end.ended_by == "done":
            self.coordinates = self.standing.stored_coordinates = leaves
            self.standing.keep()
        with self._lock:
            self._free(program)
