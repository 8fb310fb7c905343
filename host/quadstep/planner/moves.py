"""Program items → straight moves between integer step targets, with their limits.

Every target is converted to steps once, from its absolute coordinates, so
rounding never accumulates. The geometry the planner uses (length, direction)
is that of the step targets, so the plan and the steppers agree exactly.
Units from here on: mm, ticks, mm/tick, mm/tick².
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..config import MachineConfig
from .program import Dwell, JobError, LinearMove, Pause, ProbeMove, Program, SetOutputs

# A move may start up to ½ step away from its ideal start (the residual carried
# from the move before), so each axis's share of a move is bounded with
# |steps| + ½ when limits are applied; see docs/PLANNER.md.
CARRY_STEPS = 0.5


@dataclass
class MoveTable:
    """Moves in execution order (column lists; one entry per move)."""

    line: list[int] = field(default_factory=list)
    target: list[tuple[int, ...]] = field(default_factory=list)  # step target per axis
    delta: list[tuple[int, ...]] = field(default_factory=list)  # steps per axis
    length: list[float] = field(default_factory=list)  # mm
    unit: list[tuple[float, ...]] = field(default_factory=list)  # direction, mm space
    max_speed: list[float] = field(default_factory=list)  # mm/tick along the path
    accel: list[float] = field(default_factory=list)  # mm/tick² along the path
    # the move's own accel (mm/tick²), inf if none
    accel_cap: list[float] = field(default_factory=list)
    # the programmed feed (mm/tick), inf for a rapid
    feed: list[float] = field(default_factory=list)
    # G64 P / G61 at the move's start corner
    deviation: list[float | None] = field(default_factory=list)
    # stops: (number of moves before it, item), in order; the machine is at rest there (at an output
    # change only without laser mode, as GRBL waits for the motion before it changes the spindle or
    # the coolant)
    stops: list[tuple[int, Dwell | Pause | SetOutputs | ProbeMove]] = field(default_factory=list)
    # mm/tick³ along the path, inf where no axis limits it
    jerk: list[float] = field(default_factory=list)
    start: tuple[int, ...] = ()
    skipped_lines: int = 0  # moves too short to make a step

    def __len__(self) -> int:
        return len(self.line)


def _check_travel(config: MachineConfig, item: LinearMove, label: str) -> None:
    """The travel is in machine coordinates; the message names the value the line gave."""
    for i, (axis, x) in enumerate(zip(config.axes, item.target)):
        if not axis.travel_min - 1e-9 <= x <= axis.travel_max + 1e-9:
            work = item.work(i)
            where = (
                f"{axis.name} {x:.3f} mm"
                if abs(work - x) < 1e-9
                else f"{axis.name} {work:.3f} mm in {item.system} (machine {x:.3f} mm)"
            )
            raise JobError(
                f"{label} {item.line}: {where} is outside the travel "
                f"{axis.travel_min:.3f} … {axis.travel_max:.3f} mm"
            )


def build_moves(
    program: Program, config: MachineConfig, start_steps: tuple[int, ...], label: str = "line"
) -> MoveTable:
    """Check every target against the travel, then make the move table (nothing planned yet). What
    follows a probe (G38.x) is checked when the job has probed: its positions depend on where the
    probe stops."""
    for item in program.items:
        if isinstance(item, ProbeMove):
            break
        if isinstance(item, LinearMove):
            _check_travel(config, item, label)
    hz = float(config.tick_hz)
    spm = [a.steps_per_mm for a in config.axes]
    vmax = [a.max_speed / hz for a in config.axes]
    amax = [a.max_accel / (hz * hz) for a in config.axes]
    jmax = [a.max_jerk / hz**3 if a.max_jerk is not None else math.inf for a in config.axes]
    table = MoveTable(start=start_steps)
    current = start_steps
    for item in program.items:
        if not isinstance(item, LinearMove):
            table.stops.append((len(table.line), item))
            continue
        target = config.to_steps(item.target)
        delta = tuple(t - c for t, c in zip(target, current))
        if not any(delta):
            table.skipped_lines += 1
            continue
        mm = [d / s for d, s in zip(delta, spm)]
        length = math.sqrt(sum(x * x for x in mm))
        speed = item.feed / hz if item.feed is not None else math.inf
        accel = cap = item.accel / (hz * hz) if item.accel is not None else math.inf
        jerk = math.inf
        for i, d in enumerate(delta):
            if d:
                share = (abs(d) + CARRY_STEPS) / spm[i] / length
                speed = min(speed, vmax[i] / share)
                accel = min(accel, amax[i] / share)
                jerk = min(jerk, jmax[i] / share)
        table.line.append(item.line)
        table.target.append(target)
        table.delta.append(delta)
        table.length.append(length)
        table.unit.append(tuple(x / length for x in mm))
        table.max_speed.append(speed)
        table.accel.append(accel)
        table.accel_cap.append(cap)
        table.feed.append(item.feed / hz if item.feed is not None else math.inf)
        table.deviation.append(item.deviation)
        table.jerk.append(jerk)
        current = target
    return table
