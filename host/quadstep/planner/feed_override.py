"""The feed override's arithmetic: 10–200 % of every programmed feed (G1, and G2/G3's chords);
rapids keep their speed, as in GRBL, which has a separate rapid override. The planner still caps
each axis at its max_speed."""

from __future__ import annotations

from dataclasses import replace

from .program import LinearMove, Program

MIN_PERCENT, MAX_PERCENT, STEP_PERCENT = 10, 200, 10


def check_percent(percent: int) -> int:
    """`percent`, or ValueError naming the bounds."""
    if not MIN_PERCENT <= percent <= MAX_PERCENT:
        raise ValueError(f"feed override {percent} % is outside {MIN_PERCENT}–{MAX_PERCENT} %")
    return percent


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
