"""A smooth path's short moves are cruised through a little under the top speed: each is one
segment from its entry speed to its exit (planner/profile.py, CRUISE_THROUGH), not a bump of two
short ramps, so a board takes fewer segments a second for the same path, at no more than 1 % of the
time, and every check of the planner still holds."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from planner_checks import check_plan

from quadstep.config import load_config
from quadstep.planner import profile
from quadstep.planner.moves import build_moves
from quadstep.planner.plan import plan_moves
from quadstep.planner.program import LinearMove, Program

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
CRUISE_THROUGH = profile.CRUISE_THROUGH


def chords(count: int, length: float, feed: float) -> Program:
    """A 20 mm circle's chords of `length` mm, from the circle's start."""
    step = length / 20.0
    items = [
        LinearMove(k, (20.0 * math.cos(k * step), 20.0 * math.sin(k * step), 0.0), feed)
        for k in range(1, count + 1)
    ]
    return Program(items=items, lines=count)


def planned(length: float, cruise_through: float, monkeypatch: pytest.MonkeyPatch) -> tuple[int, int]:
    """Segments and ticks of 600 chords of `length` at F2400, every planner check passing."""
    monkeypatch.setattr(profile, "CRUISE_THROUGH", cruise_through)
    table = build_moves(chords(600, length, 2400.0), ROUTER, ROUTER.to_steps((20.0, 0.0, 0.0)))
    plan = plan_moves(table, ROUTER)
    assert check_plan(plan, table) == []
    return len(plan.segments), plan.duration_ticks


@pytest.mark.parametrize("length", [0.02, 0.025, 0.05])
def test_short_chords_take_fewer_segments_in_as_much_time(length: float, monkeypatch: pytest.MonkeyPatch) -> None:
    bumped, bumped_ticks = planned(length, 0.0, monkeypatch)  # each the fastest whole-tick profile
    segments, ticks = planned(length, CRUISE_THROUGH, monkeypatch)
    assert segments < bumped and ticks <= 1.01 * bumped_ticks
    if length < 0.05:  # chords of 16 and 20 ticks: one segment each, accelerating from rest too
        assert segments == 600 and bumped > 1.1 * 600
