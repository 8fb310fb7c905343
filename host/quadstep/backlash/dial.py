"""A dial indicator's reading of the backlash, for machines without a probe (the TUI's wizard;
docs/BACKLASH.md).

The indicator rests against the carriage, preloaded by a move toward it and zeroed there. Either:

- **jog back** one motor step at a time: the first steps turn the motor through the band and leave
  the carriage (and the needle) where it is; the step that first moves the needle is the first past
  the band, so the band is the steps before it;
- **move back by d** and read the indicator: the carriage came back by d − B, so B = d − the
  reading.

Both are the carriage's own motion, so no switch or probe hysteresis enters; the indicator's
resolution and the least needle motion the eye sees add to the jog-back result.

Both need moves longer than the backlash: a preload shorter than it leaves the carriage where it was
(the take-up never finishes, and either way the result is the preload itself), a move back shorter
than it never moves the carriage (the reading is 0, the result the move itself). So the moves are at
least twice the configured backlash and at least `MIN_MOVE_MM`, and a result that shows either is
refused with the reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..config import AxisConfig

MIN_MOVE_MM = (
    1.0  # the least preload and move back: the largest backlash the other methods look for
)
MOVE_FACTOR = 2.0  # and at least this many times the configured backlash
TRAVEL_SHARE = 0.25  # a move is at most this share of the axis's travel
JOG_MM = 0.01  # the larger jog back (one key), besides single steps


class DialError(ValueError):
    """A reading that cannot be a backlash, or a result that cannot be trusted (names the value, its
    limit and what to do)."""


@dataclass(frozen=True)
class DialResult:
    steps: float
    mm: float


@dataclass(frozen=True)
class DialPlan:
    """The wizard's moves for one axis: the preload and the move back (the same length), in mm and
    steps."""

    move_mm: float
    steps_per_mm: float

    @property
    def move_steps(self) -> int:
        return math.ceil(self.move_mm * self.steps_per_mm - 1e-9)

    def jog_steps(self, jog_mm: float) -> int:
        return max(1, round(jog_mm * self.steps_per_mm))


def plan(axis: AxisConfig, move_mm: float | None = None) -> DialPlan:
    """The moves for `axis`: `move_mm`, or by default the larger of `MIN_MOVE_MM` and twice its
    configured backlash; refused beyond a quarter of its travel."""
    configured = axis.backlash.mm if axis.backlash is not None else 0.0
    move = max(MIN_MOVE_MM, MOVE_FACTOR * configured) if move_mm is None else move_mm
    if move <= 0:
        raise DialError(f"{axis.name}: move = {move:g} mm: must be more than 0")
    most = TRAVEL_SHARE * (axis.travel_max - axis.travel_min)
    if move > most:
        raise DialError(
            f"{axis.name}: move = {move:g} mm: more than a quarter of its travel ({most:g} mm)"
        )
    return DialPlan(move, axis.steps_per_mm)


def _within_preload(steps: float, move: DialPlan, what: str) -> None:
    """A result within a step of the preload is the preload itself: the carriage never reached the
    indicator's side of the band."""
    if steps >= move.move_steps - 1 - 1e-9:
        raise DialError(
            f"{what}: the result, {steps:g} steps, is the preload ({move.move_steps} steps, "
            f"{move.move_mm:g} mm) within a step: the preload never took up the backlash, so the "
            "carriage never pressed the "
            "indicator: refused; preload further (a longer move) and measure again"
        )


def from_jog_back(
    steps_until_moved: int, steps_per_mm: float, move: DialPlan | None = None, last_jog: int = 1
) -> DialResult:
    """The needle first moved on step `steps_until_moved` (1, 2, …) of the jog back, during a jog of
    `last_jog` steps; `move` the preload it followed."""
    if steps_until_moved < 1:
        raise DialError(f"steps until the needle moved = {steps_until_moved}: must be at least 1")
    steps = steps_until_moved - 1
    if move is not None:  # its least is the preload already: refused, whatever the jog's size
        _within_preload(steps_until_moved - last_jog, move, "jog back")
    if last_jog > 1:
        raise DialError(
            f"the needle moved during a jog of {last_jog} steps, so the backlash is known to "
            f"{last_jog} steps only: refused; preload again and jog the last steps one at a time"
        )
    return DialResult(float(steps), steps / steps_per_mm)


def from_reading(
    distance_mm: float, reading_mm: float, steps_per_mm: float, move: DialPlan | None = None
) -> DialResult:
    """Moved back by `distance_mm` from the zeroed, preloaded indicator, which then read
    `reading_mm` (its magnitude: how far the carriage came back); `move` the preload it followed."""
    reading = abs(reading_mm)
    if distance_mm <= 0:
        raise DialError(f"distance = {distance_mm:g} mm: must be more than 0")
    if reading > distance_mm:
        raise DialError(
            f"reading = {reading:g} mm: must be at most the distance moved, {distance_mm:g} mm"
        )
    if reading == 0:
        raise DialError(
            f"reading = 0 mm after moving back {distance_mm:g} mm: the carriage never moved (the "
            "backlash is at least the move): refused; move further (a longer move) and measure "
            "again"
        )
    mm = distance_mm - reading
    if move is not None:
        _within_preload(mm * steps_per_mm, move, "move back")
    return DialResult(mm * steps_per_mm, mm)


__all__ = [
    "JOG_MM",
    "MIN_MOVE_MM",
    "DialError",
    "DialPlan",
    "DialResult",
    "from_jog_back",
    "from_reading",
    "plan",
]
