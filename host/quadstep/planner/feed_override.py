"""The overrides' arithmetic. Feed: 10–200 % of every programmed feed (G1, and G2/G3's chords);
rapids keep their speed, as in GRBL, which has a separate rapid override: 25, 50 or 100 % of the
speed the axes allow a move without a feed. Spindle: 10–200 % of every S. The planner still caps
each axis at its max_speed; no target changes, so positions stay exact."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..config import MachineConfig
from .program import Item, LinearMove, ProbeMove, Program, SetOutputs

MIN_PERCENT, MAX_PERCENT, STEP_PERCENT = 10, 200, 10


def check_percent(percent: int) -> int:
    """`percent`, or ValueError naming the bounds."""
    if not MIN_PERCENT <= percent <= MAX_PERCENT:
        raise ValueError(f"feed override {percent} % is outside {MIN_PERCENT}–{MAX_PERCENT} %")
    return percent


def clamped(percent: int) -> int:
    """`percent` brought within MIN_PERCENT–MAX_PERCENT (an override key pressed past a bound)."""
    return min(MAX_PERCENT, max(MIN_PERCENT, percent))


def scale_feeds(program: Program, percent: int) -> Program:
    """`program` with every feed move's feed times `percent` % (rapids, dwells and probes as they
    are)."""
    if percent == 100:
        return program
    factor = percent / 100.0
    items = [
        replace(item, feed=item.feed * factor)
        if isinstance(item, LinearMove) and item.feed is not None
        else item
        for item in program.items
    ]
    return replace(program, items=items)


RAPID_PERCENTS = (25, 50, 100)  # GRBL's rapid override: full, half or a quarter of the rapid speed


def check_rapid_percent(percent: int) -> int:
    """`percent`, or ValueError naming the values allowed."""
    if percent not in RAPID_PERCENTS:
        raise ValueError(f"rapid override {percent} % is not one of 25, 50, 100 %")
    return percent


def check_spindle_percent(percent: int) -> int:
    """`percent` (10–200, as the feed override), or ValueError naming the bounds."""
    if not MIN_PERCENT <= percent <= MAX_PERCENT:
        raise ValueError(f"spindle override {percent} % is outside {MIN_PERCENT}–{MAX_PERCENT} %")
    return percent


def rapid_speed(delta_mm: Sequence[float], max_speeds: Sequence[float]) -> float:
    """The path speed (mm/s) of a rapid along `delta_mm`: the fastest at which no axis exceeds its
    max_speed, what the planner gives a move without a feed."""
    length = math.sqrt(sum(d * d for d in delta_mm))
    return min(
        (vmax * length / abs(d) for d, vmax in zip(delta_mm, max_speeds) if d != 0.0),
        default=math.inf,
    )


def scale_rapids(
    program: Program, percent: int, max_speeds: Sequence[float], start_mm: Sequence[float]
) -> Program:
    """`program` with every rapid (a move without a feed) at `percent` % of its rapid speed, from
    `start_mm` (machine mm, where the program begins); the targets are untouched."""
    if percent == 100:
        return program
    factor = percent / 100.0
    here = tuple(start_mm)
    items: list[Item] = []
    for item in program.items:
        if isinstance(item, LinearMove) and item.feed is None:
            delta = [t - h for t, h in zip(item.target, here)]
            speed = rapid_speed(delta, max_speeds)
            item = replace(item, feed=speed * factor) if math.isfinite(speed) else item
        if isinstance(item, (LinearMove, ProbeMove)):
            here = item.target
        items.append(item)
    return replace(program, items=items)


def scale_spindle(program: Program, percent: int) -> Program:
    """`program` with every spindle speed (S of M3/M4) times `percent` %."""
    if percent == 100:
        return program
    factor = percent / 100.0
    items = [
        replace(item, state=replace(item.state, speed=item.state.speed * factor))
        if isinstance(item, SetOutputs)
        else item
        for item in program.items
    ]
    return replace(program, items=items)


@dataclass(frozen=True)
class Overrides:
    """The three overrides a program is planned at, %: feed (10–200), rapid (25, 50, 100) and
    spindle (10–200)."""

    feed: int = 100
    rapid: int = 100
    spindle: int = 100


def apply_overrides(
    program: Program, overrides: Overrides, config: MachineConfig, start: Sequence[int]
) -> Program:
    """`program` (beginning at stepper positions `start`) at `overrides`: the feeds scaled first,
    then the rapids (given a feed of their own, which the feed override then leaves alone), then
    every S. In laser mode the rapids keep their speed: a move without a feed keeps the laser
    off."""
    program = scale_feeds(program, overrides.feed)
    if not config.spindle.laser:
        speeds = [a.max_speed for a in config.axes]
        program = scale_rapids(program, overrides.rapid, speeds, config.to_mm(tuple(start)))
    return scale_spindle(program, overrides.spindle)
