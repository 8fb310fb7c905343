"""Measuring an axis's backlash from exact latches (docs/BACKLASH.md, "Measuring").

**Probe** (hysteresis-free, independent of the target's size and the probe's tip): a corner of the
target — a block, a touch plate's edge. The axis touches the face (the carriage is then at the face,
pushed toward it) and backs off by e steps beyond its overshoot; the test axis then leaves and comes
back along the neighbouring face, which it can touch only if the carriage is still at the face. A
closing edge has no hysteresis, and the test asks only "contact or not", so the largest e that still
touches is the backlash: the first e − B steps of the back-off move the motor inside the band, not
the carriage. The largest e is found by doubling, then halving (a test that misses needs a new
touch; one that hits does not).

**Switch**: approach until the switch closes, reverse until it opens, approach again: each interval
between two edges is the backlash plus the switch's own hysteresis, rounded up by 0 … 2 steps (0
only when both edges fall exactly on a motor step). The hysteresis, calibrated once
(`switch_hysteresis`, from a backlash known by the probe), is subtracted.

Both run k tries and refuse a result whose tries spread more than a bound or more than one step
(latches are exact: a wider spread is a bounce or a loose part, and the mean is no longer within a
step), and one that is negative beyond the rounding (−1 step); a negative result within it is 0.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable
from dataclasses import asdict, dataclass

from ..config import AxisConfig, MachineConfig
from ..link import AlarmError, input_status
from ..protocol import AlarmCode, Input
from .errors import MachineError
from .inputs import switch_input
from .machine import Machine
from .raw_moves import RawMoves
from .units import step_direction

Progress = Callable[[str], None]

# Per axis, the probe's default corner: the direction toward the face measured, and the axis that
# tests the neighbouring face (toward +): the −X, −Y corner of a block for X and Y, a plate's −X
# edge for Z.
PROBE_SETUP = {"X": (1, "Y"), "Y": (1, "X"), "Z": (-1, "X"), "A": (1, "X")}
ROUNDING = 1.0  # steps: a result is within this of the backlash, so no try may spread more


class MeasureError(MachineError):
    """The measurement could not be made (no contact, a switch not found, a result too
    scattered)."""


@dataclass(frozen=True)
class Measurement:
    """A backlash measured k times: each try's steps, their mean and spread, in steps and mm."""

    axis: str
    method: str
    tries: list[float]  # steps, each try
    steps: float  # their mean
    mm: float
    spread_steps: float  # largest − smallest
    spread_mm: float
    bound_mm: float  # the largest spread accepted
    # switch: backlash + hysteresis, before the hysteresis is taken off
    sum_steps: float | None = None
    hysteresis_mm: float | None = None  # switch: the calibrated hysteresis taken off
    negative_steps: float = 0.0  # the mean when it came out below 0 (then steps and mm are 0)

    @property
    def refused(self) -> str:
        """Why the result cannot be trusted ("" when it can)."""
        if self.negative_steps < -ROUNDING - 1e-9:
            cause = (
                "the calibrated switch_hysteresis is too large: calibrate it again"
                if self.method == "switch"
                else "check the setup"
            )
            return (
                f"the result is {self.negative_steps:g} steps, negative beyond the rounding "
                f"(−{ROUNDING:g} step): {cause}"
            )
        if self.spread_mm > self.bound_mm + 1e-12:
            return (
                f"the tries spread {self.spread_mm:.4f} mm, more than --max-spread "
                f"{self.bound_mm:g} mm"
            )
        if self.spread_steps > ROUNDING + 1e-9:
            bounce = " (a bouncing switch: raise [inputs] debounce_ms)"
            why = bounce if self.method == "switch" else ""
            return (
                f"the tries spread {self.spread_steps:g} steps, more than {ROUNDING:g} step: a "
                f"latch came late{why}"
            )
        return ""

    @property
    def accepted(self) -> bool:
        return not self.refused

    @property
    def whole_steps(self) -> int:
        return max(0, round(self.steps))

    def as_dict(self) -> dict[str, object]:
        return {
            **asdict(self),
            "accepted": self.accepted,
            "refused": self.refused,
            "whole_steps": self.whole_steps,
        }


def _result(
    axis: AxisConfig, method: str, tries: list[float], bound_mm: float, **extra: float | None
) -> Measurement:
    """The mean and spread of the tries; a negative mean is 0 (a backlash is not below 0) and kept
    to judge whether it is within the rounding."""
    spm = axis.steps_per_mm
    mean = statistics.fmean(tries)
    spread = max(tries) - min(tries)
    negative = min(mean, 0.0)
    mean = max(mean, 0.0)
    return Measurement(
        axis.name,
        method,
        tries,
        mean,
        mean / spm,
        spread,
        spread / spm,
        bound_mm,
        **extra,
        negative_steps=negative,
    )


def _axis(machine: Machine, name: str) -> int:
    names = machine.config.axis_names
    if name.upper() not in names:
        raise MeasureError(f"axis {name}: not configured ({', '.join(names)})")
    return names.index(name.upper())


def measure_with_probe(
    machine: Machine,
    name: str,
    *,
    toward: int,
    test: str,
    test_toward: int,
    tries: int = 5,
    search: float = 10.0,
    clear: float = 3.0,
    largest: float = 1.0,
    feed: float = 2.0,
    max_spread: float = 0.01,
    on_progress: Progress | None = None,
) -> Measurement:
    """The probe at a corner: `name` moves toward (+1/−1, machine direction) the face it measures,
    `test` moves toward the neighbouring face; the probe starts outside the first face, and less
    than `clear` mm inside the second's edge along the test axis. Distances in mm, `feed` in
    mm/s."""
    a, t = _axis(machine, name), _axis(machine, test)
    if a == t:
        raise MeasureError("the test axis must be another axis than the one measured")
    axis, test_axis = machine.config.axes[a], machine.config.axes[t]
    say = on_progress or (lambda text: None)
    values: list[float] = []
    with machine.procedure(f"backlash {axis.name}"):
        moves = RawMoves(machine, feed)
        if input_status(machine.link).is_active(Input.PROBE):
            raise MeasureError("the probe touches already: move it clear of the target")
        corner = _Corner(
            machine,
            moves,
            a,
            t,
            axis,
            test_axis,
            s_a=step_direction(axis, toward),
            s_t=step_direction(test_axis, test_toward),
            reach=round(search * axis.steps_per_mm),
            back=round(clear * test_axis.steps_per_mm),
            top=round(largest * axis.steps_per_mm),
            search=search,
            clear=clear,
            largest=largest,
        )
        for k in range(tries):
            low = corner.measure()
            values.append(float(low))
            say(f"{axis.name}: try {k + 1}/{tries}: {low} steps ({low / axis.steps_per_mm:.4f} mm)")
        moves.move(a, -corner.s_a * corner.reach // 4)  # leave the target free
    return _result(axis, "probe", values, max_spread)


@dataclass
class _Corner:
    """One probe corner's moves (steps): touch the face along axis `a`, back off, test the
    neighbouring face along axis `t`."""

    machine: Machine
    moves: RawMoves
    a: int
    t: int
    axis: AxisConfig
    test_axis: AxisConfig
    s_a: int
    s_t: int
    reach: int
    back: int
    top: int
    search: float
    clear: float
    largest: float
    overshoot: int = 0
    out: int = 0  # steps backed off beyond the overshoot

    def measure(self) -> int:
        """One try: the largest back-off (steps) after which the test still touches."""
        self.touch()
        low, e, high = 0, 1, None
        while high is None:  # doubling, without a new touch while it still hits
            if e > self.top:
                raise MeasureError(
                    f"{self.axis.name}: the backlash is more than {self.largest:g} mm (--max)"
                )
            self.back_off(e)
            if self.hits():
                low, e = e, e * 2
            else:
                high = e
        missed = True
        while high - low > 1:  # halving: a miss needs a new touch first
            middle = (low + high) // 2
            if missed:
                self.touch()
            self.back_off(middle)
            missed = not self.hits()
            low, high = (low, middle) if missed else (middle, high)
        return low

    def touch(self) -> None:
        """Touch the face; the overshoot past the latch (steps)."""
        # in contact from the last test: away first
        if input_status(self.machine.link).is_active(Input.PROBE):
            self.moves.move(self.a, -self.s_a * (self.top + self.reach // 10))
        latched = self.moves.until(self.a, self.s_a * self.reach, Input.PROBE, 1)
        if latched is None:
            raise MeasureError(f"{self.axis.name}: no contact within {self.search:g} mm")
        self.overshoot, self.out = abs(self.moves.motor[self.a] - latched), 0

    def back_off(self, e: int) -> None:
        self.moves.move(
            self.a, -self.s_a * (e - self.out + (self.overshoot if self.out == 0 else 0))
        )
        self.out = e

    def hits(self) -> bool:
        """Away along the test axis and back: does it touch the neighbouring face?"""
        self.moves.move(self.t, -self.s_t * self.back)
        if input_status(self.machine.link).is_active(Input.PROBE):
            raise MeasureError(
                f"{self.test_axis.name}: the probe still touches {self.clear:g} mm away from the "
                "face"
            )
        return self.moves.until(self.t, self.s_t * self.back, Input.PROBE, 1) is not None


def switch_sums(
    machine: Machine, a: int, end: str, tries: int, search: float, feed: float, say: Progress
) -> list[float]:
    """Per try, backlash + the switch's hysteresis in steps: the mean of two intervals between its
    edges."""
    axis = machine.config.axes[a]
    which = switch_input(input_status(machine.link).present, a, end)
    s = step_direction(axis, -1 if end == "min" else 1)  # toward the switch, in steps
    reach = round(search * axis.steps_per_mm)
    sums: list[float] = []
    with machine.procedure(f"backlash {axis.name}"):
        moves = RawMoves(machine, feed)

        def edge(level: int, direction: int) -> int:
            latched = moves.until(a, direction * reach, which, level)
            if latched is None:
                raise MeasureError(
                    f"{axis.name}: the switch did not {'close' if level else 'open'} within "
                    f"{search:g} mm ({which.name})"
                )
            return latched

        try:
            if input_status(machine.link).is_active(which):
                edge(0, -s)
            edges = [edge(1, s)]
            for k in range(tries):
                edges += [edge(0, -s), edge(1, s)]
                first, second = abs(edges[-2] - edges[-3]), abs(edges[-1] - edges[-2])
                # Each interval is the sum rounded up by 0 … 2 steps: the middle of that range.
                sums.append((first + second) / 2 - 1)
                say(f"{axis.name}: try {k + 1}/{tries}: backlash + hysteresis {sums[-1]:g} steps")
            edge(0, -s)
            moves.move(a, -s * reach // 10)  # off the switch
        except AlarmError as exc:
            if exc.alarm.code != AlarmCode.HARD_LIMIT:
                raise
            raise MeasureError(bounced(machine, which, exc)) from None
    return sums


def bounced(machine: Machine, which: Input, exc: AlarmError) -> str:
    """A hard limit during a switch measurement: the switch closed again after its opening was
    accepted, which is a contact bouncing for longer than the debounce."""
    debounce = machine.config.inputs.debounce_ms
    return (
        f"the switch bounced ({which.name} closed again after its edge was accepted, at positions "
        f"{list(exc.alarm.position)}): its bounce lasts longer than [inputs] debounce_ms = "
        f"{debounce:g} ms; raise debounce_ms (a few ms) and measure again. The board is in ALARM "
        "HARD_LIMIT: STOP (Ctrl+X in the TUI) clears it"
    )


def measure_with_switch(
    machine: Machine,
    name: str,
    *,
    end: str | None = None,
    tries: int = 5,
    search: float = 5.0,
    feed: float = 1.0,
    max_spread: float = 0.01,
    on_progress: Progress | None = None,
) -> Measurement:
    """The axis's limit switch (at `end`, default its homing end): backlash + hysteresis − the
    calibrated hysteresis."""
    a = _axis(machine, name)
    axis = machine.config.axes[a]
    hysteresis = axis.backlash.switch_hysteresis if axis.backlash is not None else None
    if hysteresis is None:
        raise MeasureError(
            f"{axis.name}: the switch's hysteresis is not calibrated ([axes.backlash] "
            "switch_hysteresis): `quadstep backlash calibrate-switch` finds it once the backlash "
            "is known (from the probe)"
        )
    end = switch_end(machine.config, axis.name, end)
    sums = switch_sums(machine, a, end, tries, search, feed, on_progress or (lambda text: None))
    h = hysteresis * axis.steps_per_mm
    result = _result(axis, "switch", [x - h for x in sums], max_spread, hysteresis_mm=hysteresis)
    return Measurement(**{**asdict(result), "sum_steps": statistics.fmean(sums)})


def known_backlash(config: MachineConfig, name: str, given: float | None = None) -> float:
    """The backlash (mm) a switch's calibration takes off: `given`, else the configuration's (as
    measured with the probe)."""
    if given is not None:
        return given
    axis = config.axes[config.axis_names.index(name)] if name in config.axis_names else None
    if axis is None or axis.backlash is None:
        raise MeasureError(
            f"{name}: no backlash known: measure it with the probe first, or give --backlash MM"
        )
    return axis.backlash.mm


def switch_end(config: MachineConfig, name: str, end: str | None = None) -> str:
    """Which end's switch a switch measurement uses: `end`, else the homing end (min without
    homing)."""
    axis = config.axes[config.axis_names.index(name)]
    return end or (axis.homing.end if axis.homing is not None else "min")


def calibrate_switch(
    machine: Machine,
    name: str,
    backlash_mm: float,
    *,
    end: str | None = None,
    tries: int = 5,
    search: float = 5.0,
    feed: float = 1.0,
    on_progress: Progress | None = None,
) -> float:
    """The switch's hysteresis (mm): what is left of backlash + hysteresis once the known backlash
    is taken off."""
    a = _axis(machine, name)
    axis = machine.config.axes[a]
    end = switch_end(machine.config, axis.name, end)
    sums = switch_sums(machine, a, end, tries, search, feed, on_progress or (lambda text: None))
    return max(0.0, statistics.fmean(sums) / axis.steps_per_mm - backlash_mm)


__all__ = [
    "PROBE_SETUP",
    "MeasureError",
    "Measurement",
    "calibrate_switch",
    "known_backlash",
    "measure_with_probe",
    "measure_with_switch",
    "switch_end",
]
