"""A dial indicator's reading of the backlash, for machines without a probe (the TUI's wizard;
docs/BACKLASH.md).

The indicator rests against the carriage, preloaded by a move toward it and zeroed there. Either:

- **jog back** one motor step at a time: the first steps turn the motor through the band and leave
the
  carriage (and the needle) where it is; the step that first moves the needle is the first past the
  band, so the band is the steps before it;
- **move back by d** and read the indicator: the carriage came back by d − B, so B = d − the
reading.

Both are the carriage's own motion, so no switch or probe hysteresis enters; the indicator's
resolution and the least needle motion the eye sees add to the jog-back result.
"""

from __future__ import annotations

from dataclasses import dataclass


class DialError(ValueError):
    """A reading that cannot be a backlash (names the value and its limit)."""


@dataclass(frozen=True)
class DialResult:
    steps: float
    mm: float


def from_jog_back(steps_until_moved: int, steps_per_mm: float) -> DialResult:
    """The needle first moved on step `steps_until_moved` (1, 2, …) of the jog back."""
    if steps_until_moved < 1:
        raise DialError(f"steps until the needle moved = {steps_until_moved}: must be at least 1")
    steps = steps_until_moved - 1
    return DialResult(float(steps), steps / steps_per_mm)


def from_reading(distance_mm: float, reading_mm: float, steps_per_mm: float) -> DialResult:
    """Moved back by `distance_mm` from the zeroed, preloaded indicator, which then read
    `reading_mm` (its magnitude: how far the carriage came back)."""
    reading = abs(reading_mm)
    if distance_mm <= 0:
        raise DialError(f"distance = {distance_mm:g} mm: must be more than 0")
    if reading > distance_mm:
        raise DialError(
            f"reading = {reading:g} mm: must be at most the distance moved, {distance_mm:g} mm"
        )
    mm = distance_mm - reading
    return DialResult(mm * steps_per_mm, mm)


__all__ = ["DialError", "DialResult", "from_jog_back", "from_reading"]
