"""A job going on after a feed hold (or a pause, or a feed override) plans the rest of itself from
where its machine stands: what the job asks of the machine for that (Restream, machine/job.py), and
the machine's answer (MachineRestream)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from ..coordinates import WorkCoordinates
from ..planner.plan import Plan
from ..planner.program import ProbeMove
from .motion import MotionEnd
from .probing import ProbingMachine
from .probing import probe as run_probe
from .takeups import StreamPlan


class Restream(Protocol):
    """What the machine does for a job going on after a feed hold: the band where the hold left it
    and the position at rest (take-ups excluded), then the rest of the job with its take-ups."""

    def held(self, end: MotionEnd) -> tuple[int, ...]: ...

    def stream(self, plan: Plan) -> StreamPlan: ...

    def restream(self, plan: Plan, running: StreamPlan) -> StreamPlan: ...

    def swap(self, streamed: StreamPlan, ticks: int = 0, motor: Sequence[int] = ()) -> None: ...

    def at_rest(self) -> tuple[int, ...]: ...

    def position(self) -> tuple[int, ...]: ...

    def coordinates(self) -> WorkCoordinates: ...

    def probe(self, probe: ProbeMove) -> tuple[float, ...]: ...

    def adopt(self, coordinates: WorkCoordinates) -> None: ...


class RestreamingMachine(ProbingMachine, Protocol):
    """What a job going on after a feed hold uses of its Machine (machine.py)."""

    coordinates: WorkCoordinates  # in force

    @property
    def position_mm(self) -> tuple[float, ...]: ...


class MachineRestream:
    """A job of this machine goes on after a feed hold (machine/job.py, Restream)."""

    def __init__(self, machine: RestreamingMachine) -> None:
        self.machine = machine
        self.standing = machine.standing

    def held(self, end: MotionEnd) -> tuple[int, ...]:
        status = self.standing.link.status()
        self.standing.rest(status.position, end.hold_tick, False)
        return self.standing.position

    def at_rest(self) -> tuple[int, ...]:
        """Where a job stands at its pause, the band as its take-ups left it there."""
        status = self.standing.link.status()
        self.standing.rest(status.position, status.motion_ticks, False)
        return self.standing.position

    def position(self) -> tuple[int, ...]:
        return self.standing.position

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
        entry = running.compensated.entry
        compensated = self.standing.takeups.compensate(plan.segments, plan.pauses, band, entry)
        return StreamPlan(plan.config, compensated.stream, compensated.pauses, compensated, plan)

    def swap(self, streamed: StreamPlan, ticks: int = 0, motor: Sequence[int] = ()) -> None:
        """The running job goes on as `streamed`, which begins as it did, or `ticks` and `motor`
        into it (it let go of what ran)."""
        self.standing.takeups.swap(streamed.compensated, ticks, motor)

    def stream(self, plan: Plan) -> StreamPlan:
        compensated = self.standing.takeups.compensate(plan.segments, plan.pauses)
        status = self.standing.link.status()
        self.standing.takeups.begin(
            compensated, status.position[: self.standing.axis_count], status.motion_ticks
        )
        return StreamPlan(plan.config, compensated.stream, compensated.pauses, compensated, plan)
