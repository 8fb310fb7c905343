"""The dial-indicator measurement's moves and arithmetic (machine/dial.py) on the emulator's
simulated machine, the indicator read from the carriage in its trace: with backlash 0 … 1.2 mm on Z,
its carriage last moved away from the indicator, every result is within a step of the truth or
refused with the reason; a longer move then measures what a short one refused."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from backlash_helpers import STEPS_PER_MM, TICK_HZ, backlash_config
from quadstep.backlash.dial import DialError, DialResult
from quadstep.config import MachineConfig
from quadstep.emulator import Emulator
from quadstep.machine import Machine, Target, open_machine
from quadstep.machine.dial import DialMeasurement

StartEmulator = Callable[..., Emulator]
Z = 2
TRUTHS_MM = (0.0, 0.0033, 0.2219, 0.5, 1.2)


class Indicator:
    """A dial indicator against Z's carriage, read from the emulator's trace (flushed whenever it
    rests)."""

    def __init__(self, trace: Path, start: float) -> None:
        self.trace, self.start = trace, start
        self.zero = self.carriage()

    def carriage(self) -> float:
        last = self.start
        for line in self.trace.read_text().splitlines()[1:]:
            fields = line.split(",")  # tick, axis, direction, motor, carriage
            if int(fields[1]) == Z:
                last = float(fields[4])
        return last

    def zeroed(self) -> None:
        self.zero = self.carriage()

    def reading_mm(self) -> float:
        return (self.carriage() - self.zero) / STEPS_PER_MM

    def moved(self) -> bool:
        return self.carriage() != self.zero


@contextmanager
def z_axis(
    start_emulator: StartEmulator,
    tmp_path: Path,
    truth_mm: float,
    config: MachineConfig | None = None,
    last: int = -1,
) -> Iterator[tuple[Machine, Indicator]]:
    """Z with `truth_mm` of backlash, its carriage last moved in `last` (−1: away from an indicator
    on its + side, so trailing the motor on the + side of its band), at 0."""
    b = truth_mm * STEPS_PER_MM
    sim = tmp_path / "dial.toml"
    sim.write_text(
        f"[[axis]]\n[[axis]]\n[[axis]]\nstart = {round(last * b / 2)}\ncarriage = "
        f"{round(last * b / 2) - last * b / 2}\nbacklash = {b}\n"
    )
    trace = tmp_path / "trace.csv"
    emu = start_emulator(
        free=True, tick_hz=TICK_HZ, axes=3, trace=trace, extra_args=["--machine", str(sim)]
    )
    with open_machine(
        Target(emulator=True), config or backlash_config((0, 0, 0)), emulator=emu
    ) as machine:
        yield machine, Indicator(trace, round(last * b / 2) - last * b / 2)


def by_jogging(dial: DialMeasurement, indicator: Indicator) -> DialResult:
    """The user: preload, zero, jog back in large steps to get close, then one step at a time; a
    needle that moves within a large step is refused, so again, the large steps stopping short of
    it."""
    dial.preload()
    indicator.zeroed()
    large = dial.plan.jog_steps(dial.jog_mm)
    while not indicator.moved():
        dial.jog(large=True)
    try:
        return (
            dial.jogged()
        )  # refused: the needle moved within a large step, or at the preload itself
    except DialError as exc:
        if f"the needle moved during a jog of {large} steps" not in str(exc):
            raise
    close = (
        dial.count - 2 * large
    )  # a step or two short: the band is found again from a new preload
    dial.preload()
    indicator.zeroed()
    while dial.count + large <= close:
        dial.jog(large=True)
    while not indicator.moved():
        dial.jog()
    return dial.jogged()


def by_reading(dial: DialMeasurement, indicator: Indicator) -> DialResult:
    dial.preload()
    indicator.zeroed()
    dial.move_back()
    return dial.read(round(indicator.reading_mm(), 4))  # a 0.1 µm indicator: a quarter of a step


def measured(dial: DialMeasurement, indicator: Indicator) -> list[DialResult | str]:
    """Both methods: each result or its refusal."""
    results: list[DialResult | str] = []
    for method in (by_jogging, by_reading):
        try:
            results.append(method(dial, indicator))
        except DialError as exc:
            results.append(str(exc))
    return results


@pytest.mark.parametrize("last", (-1, 1), ids=("last-moved-away", "last-moved-toward"))
@pytest.mark.parametrize("truth_mm", TRUTHS_MM)
def test_every_result_is_within_a_step_or_refused_with_the_reason(
    start_emulator: StartEmulator, tmp_path: Path, truth_mm: float, last: int
) -> None:
    with z_axis(start_emulator, tmp_path, truth_mm, last=last) as (machine, indicator):
        dial = DialMeasurement(machine, "Z")
        assert dial.plan.move_mm == 1.0  # no backlash configured: the documented minimum
        results = measured(dial, indicator)
        if truth_mm < dial.plan.move_mm:
            for result in results:
                assert isinstance(result, DialResult), results
                assert abs(result.steps - truth_mm * STEPS_PER_MM) <= 1.0, (results, truth_mm)
            return
        jogged, read = (
            results  # 1.2 mm: the 1 mm preload never took the backlash up, or the move back
        )
        assert isinstance(jogged, str) and "the preload never took up the backlash" in jogged, (
            jogged
        )
        never = "reading = 0 mm after moving back 1 mm: the carriage never moved"
        assert isinstance(read, str) and (never in read or "the preload never" in read), read
        dial.resize(2.0)  # a longer move: now both measure it
        for result in measured(dial, indicator):
            assert (
                isinstance(result, DialResult)
                and abs(result.steps - truth_mm * STEPS_PER_MM) <= 1.0
            ), result


def test_the_moves_are_twice_the_configured_backlash_and_within_the_travel(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    config = backlash_config((0, 0, 0.6))
    with z_axis(start_emulator, tmp_path, 0.2219, config) as (machine, indicator):
        dial = DialMeasurement(machine, "Z")
        assert dial.plan.move_mm == 1.2 and dial.plan.move_steps == 480
        for result in measured(dial, indicator):
            assert (
                isinstance(result, DialResult) and abs(result.steps - 0.2219 * STEPS_PER_MM) <= 1.0
            ), result
        with pytest.raises(
            DialError, match="Z: move = 600 mm: more than a quarter of its travel \\(500 mm\\)"
        ):
            dial.resize(600)


def test_a_preload_shorter_than_the_backlash_is_refused_not_reported_as_the_backlash(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    """0.2 mm moves on 0.2219 mm of backlash, the carriage last moved away: both methods used to
    give 0.2000 mm, the preload itself."""
    with z_axis(start_emulator, tmp_path, 0.2219) as (machine, indicator):
        dial = DialMeasurement(machine, "Z", move_mm=0.2)
        jogged, read = measured(dial, indicator)
        assert (
            isinstance(jogged, str) and "is the preload (80 steps, 0.2 mm) within a step" in jogged
        ), jogged
        assert isinstance(read, str) and "refused" in read, read


def test_jogging_back_past_the_preload_is_overdue(
    start_emulator: StartEmulator, tmp_path: Path
) -> None:
    """A 0.1 mm preload on 1.2 mm of backlash, the carriage last moved toward the indicator: the
    needle moves only 480 steps back, so a step past the preload's it is overdue (the wizard says
    so)."""
    with z_axis(start_emulator, tmp_path, 1.2, last=1) as (machine, indicator):
        dial = DialMeasurement(machine, "Z", move_mm=0.1)
        dial.preload()
        indicator.zeroed()
        while dial.count + 4 <= dial.plan.move_steps:
            dial.jog(large=True)
        dial.jog()
        assert (
            dial.count == 41 and not dial.overdue
        )  # this step can still be the first past the band
        dial.jog()
        assert dial.overdue and not indicator.moved()
