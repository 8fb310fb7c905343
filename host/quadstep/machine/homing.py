"""The homing cycle (GRBL's), driven by the host from exact latches (docs/INPUTS.md, Homing).

Per axis in the configured order (Z first by default): if its switch is closed already, pull off
until it opens; seek toward it fast until it closes (a PROBE on the switch's input: the firmware
latches the edge and holds); back off beyond the hold's overshoot; locate it slowly; pull off. The
slow approach's latched step position is where the switch's point is: the axis's step count is
redefined so that it reads `switch_at` there (by default `pull_off` beyond the travel's end), and
the pull-off ends `pull_off` from that point: by default at the travel's end, so that every move
inside the travel stays clear of the switch (GRBL's machine zero is on its switch, and a park there
stops on a hard limit). The switch is always approached from the same side at the same speed, so
the backlash is taken up the same way each time and machine zero repeats to the step.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..config import AxisConfig, MachineConfig
from ..kernel.fixed import MAX_AXES
from ..link import input_status, until_input
from ..planner.plan import plan_program
from ..planner.program import LinearMove, Program
from ..protocol import Probe, ProbeMissed, Segment
from ..protocol.wire import four_axes
from .errors import MachineError
from .inputs import switch_input
from .machine import Machine, Procedure
from .units import braking_steps

Progress = Callable[[str], None]
TIMEOUT = 600.0  # s for any one approach


class HomingError(MachineError):
    """A switch was not found (or did not open) where the cycle looked for it."""


@dataclass(frozen=True)
class AxisHomed:
    """An axis homed: where its switch closed on the slow approach (steps before zero was set) and
    where the axis stands now (after the pull-off), both in the new machine coordinates."""

    name: str
    switch_steps: int
    position_steps: int
    position_mm: float


def unbounded(config: MachineConfig) -> MachineConfig:
    """The configuration with no travel limits: before homing, the travel is not known yet."""
    axes = tuple(
        a.model_copy(update={"travel_min": -100_000.0, "travel_max": 100_000.0})
        for a in config.axes
    )
    return config.model_copy(update={"axes": axes})


def straight(
    config: MachineConfig, start: Sequence[int], axis: int, mm: float, feed: float, axis_count: int
) -> list[Segment]:
    """One move of `mm` along `axis` at `feed` mm/s from rest to rest, from step position `start`,
    as segments for a firmware of `axis_count` axes."""
    target = list(config.to_mm(tuple(start)))
    target[axis] += mm  # machine mm: the axis's `invert` is the step conversion's
    program = Program(items=[LinearMove(line=1, target=tuple(target), feed=feed)], lines=1)
    plan = plan_program(program, config, tuple(start))
    return plan.quadratic_segments()


def home(
    machine: Machine, axes: Sequence[str] | None = None, on_progress: Progress | None = None
) -> list[AxisHomed]:
    """Home the named axes (default: the configured order) one at a time; returns each one's result.
    Raises HomingError (a switch not found within the travel and a half), and what the link raises
    (a hard limit of another axis, the abort button: AlarmError; the user's stop: Stopped)."""
    config = machine.config
    order = (
        config.homing_axes
        if axes is None
        else tuple(config.axis_names.index(n.upper()) for n in axes)
    )
    for i in order:
        if config.axes[i].homing is None:
            raise HomingError(
                f"axis {config.axes[i].name} has no [axes.homing] in the configuration"
            )
    if not order:
        raise HomingError("no axis has [axes.homing] in the configuration")
    say = on_progress or (lambda text: None)
    results = []
    with machine.procedure("home") as procedure:
        for i in order:
            results.append(_home_axis(machine, procedure, i, say))
    machine.standing.set_homed(len(order) == len([a for a in config.axes if a.homing is not None]))
    return results


def _home_axis(machine: Machine, procedure: Procedure, i: int, say: Progress) -> AxisHomed:
    config, link = machine.config, machine.link
    axis: AxisConfig = config.axes[i]
    homing = axis.homing
    assert homing is not None  # home() takes only axes with [axes.homing]
    free = unbounded(config)
    toward = -1.0 if homing.end == "min" else 1.0  # in machine mm
    which = switch_input(input_status(link).present, i, homing.end)
    decel = four_axes(list(machine.decels) + [0] * (MAX_AXES - len(machine.decels)))
    n = link.axis_count
    span = (axis.travel_max - axis.travel_min) * 1.5
    overshoot = (
        braking_steps(homing.seek * axis.steps_per_mm / config.tick_hz, machine.decels[i])
        / axis.steps_per_mm
    )
    back = overshoot + homing.pull_off

    def at() -> list[int]:
        return list(machine.position) + [0] * (n - machine.axis_count)

    def approach(level: int, mm: float, feed: float, what: str) -> tuple[int, ...]:
        """Where (take-ups excluded) the switch reached `level` on a move of `mm`."""
        segments = machine.standing.takeup_stream(straight(free, at(), i, mm, feed, n))
        end = until_input(
            link,
            Probe(input=which, level=level, decel=decel),
            segments,
            TIMEOUT,
        )
        if isinstance(end, ProbeMissed):
            machine.standing.rested()
            raise HomingError(f"axis {axis.name}: {what} within {abs(mm):.1f} mm ({which.name})")
        latched = machine.standing.shown(end.position, end.motion_ticks)
        machine.standing.rested(end.motion_ticks)
        return latched

    def move(mm: float, feed: float) -> None:
        stream = link.generation  # a hold from elsewhere (the feed hold button) ends the move
        for segment in machine.standing.takeup_stream(straight(free, at(), i, mm, feed, n)):
            link.send(segment, TIMEOUT, stream)
        link.wait_idle(TIMEOUT, stream)
        machine.standing.rested()

    if input_status(link).is_active(which):
        say(f"{axis.name}: switch closed already, pulling off")
        approach(
            0, -toward * (back + homing.pull_off) * 4, homing.locate, "the switch did not open"
        )
    say(f"{axis.name}: seeking the switch at {homing.seek:g} mm/s")
    approach(1, toward * span, homing.seek, "no switch")
    say(f"{axis.name}: backing off {back:.2f} mm")
    move(-toward * back, homing.seek)
    if input_status(link).is_active(which):
        approach(0, -toward * homing.pull_off * 4, homing.locate, "the switch did not open")
    say(f"{axis.name}: locating the switch at {homing.locate:g} mm/s")
    hit = approach(1, toward * back * 2, homing.locate, "no switch on the slow approach")
    switch_mm = axis.switch_at
    assert switch_mm is not None  # home() takes only axes with [axes.homing]
    zero_shift = axis.to_steps(switch_mm) - hit[i]
    machine.set_position({i: machine.position[i] + zero_shift}, within=procedure)
    # to pull_off from the switch's point, not from where the hold stopped past it: by default the
    # travel's end, whatever the overshoot
    move(switch_mm - toward * homing.pull_off - axis.to_mm(machine.position[i]), homing.locate)
    position = machine.position[i]
    say(f"{axis.name}: homed, switch at {switch_mm:g} mm, now at {axis.to_mm(position):.3f} mm")
    return AxisHomed(axis.name, hit[i] + zero_shift, position, axis.to_mm(position))
