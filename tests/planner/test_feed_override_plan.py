"""Planning again from a move boundary (a feed override while a job runs): the state carried over is the plan's
own — at 100 % the rest comes out segment for segment as first planned, from every boundary — and at other
overrides every move still lands exactly, the feeds scaled and the rapids not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.machine.override import boundary_at, feeds_at, replan_from, replan_scurve
from quadstep.planner.feed_override import scale_feeds

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
DEMO = REPO / "examples" / "demo.gcode"


def arrays(plan) -> dict[str, np.ndarray]:  # noqa: ANN001
    return {k: np.asarray(v) for k, v in plan.segments.numpy().items()}


def test_at_100_percent_the_rest_planned_from_any_boundary_is_the_plan_itself() -> None:
    job = load_job(DEMO, CONFIG)
    first = arrays(job.plan)
    for move in range(1, job.plan.moves, 3):
        again = replan_from(job.program, job.plan, move, feeds_at(100), "line")
        assert again.end == job.plan.end and list(again.move_ends) == list(job.plan.move_ends)
        for key, column in arrays(again).items():
            assert np.array_equal(column, first[key]), (move, key)


@pytest.mark.parametrize("percent", [10, 50, 150, 200])
def test_from_a_boundary_every_move_lands_and_the_feeds_are_scaled(percent: int) -> None:
    job = load_job(DEMO, CONFIG)
    move = job.plan.moves // 3
    again = replan_from(job.program, job.plan, move, feeds_at(percent), "line")
    assert again.end == job.plan.end
    index = job.plan.move_ends[move - 1]
    assert again.move_ends[:move] == job.plan.move_ends[:move]
    before, after = arrays(job.plan), arrays(again)
    for key in before:  # what was sent stays as it was
        assert np.array_equal(after[key][:index], before[key][:index])
    # the rest takes as long as the same rest planned from rest at that override, near enough: the boundary
    # only changes how the first move begins
    alone = load_job(DEMO, CONFIG, feed_override=percent).plan
    tail = int(after["n"][index:].astype(np.int64).sum())
    rest_alone = int(
        np.asarray(alone.segments.numpy()["n"])[alone.move_ends[move - 1] :].astype(np.int64).sum()
    )
    assert tail == pytest.approx(rest_alone, rel=0.02)
    # the boundary's state is where the move before ended: its target, within half a step of the ideal
    state = boundary_at(job.plan, move)
    assert all(abs(i - 8192 * p) < 4096 for i, p in zip(state.ideal2, state.position))


def test_rapids_keep_their_speed() -> None:
    job = load_job(DEMO, CONFIG)
    slow = scale_feeds(job.program, 10)
    for a, b in zip(job.program.items, slow.items):
        feed = getattr(a, "feed", None)
        if getattr(a, "target", None) is not None and feed is None:
            assert getattr(b, "feed", None) is None
        elif feed is not None and type(a).__name__ == "LinearMove":
            assert getattr(b, "feed") == pytest.approx(feed / 10)


def test_a_jerk_limited_plan_planned_again_from_a_boundary_at_100_percent_is_the_plan_itself() -> None:
    """The S-curve re-plan: the moves before the boundary planned again as they were, the rest going
    on from the planner's state there; at 100 % that is the plan, segment for segment."""
    config = CONFIG.model_copy(
        update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)})
    job = load_job(DEMO, config)
    first = list(job.plan.segments.segments())
    for move in (1, job.plan.moves // 2, job.plan.moves - 1):
        again = replan_scurve(job.program, job.plan, move, feeds_at(100), feeds_at(100), "line")
        assert again.end == job.plan.end and list(again.move_ends) == list(job.plan.move_ends)
        assert list(again.segments.segments()) == first, move
        assert again.outputs == job.plan.outputs and again.pauses == job.plan.pauses


def test_a_jerk_limited_plan_at_50_percent_from_a_boundary_lands_and_keeps_what_came_before() -> None:
    config = CONFIG.model_copy(
        update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)})
    job = load_job(DEMO, config)
    move = job.plan.moves // 3
    again = replan_scurve(job.program, job.plan, move, feeds_at(50), feeds_at(100), "line")
    assert again.end == job.plan.end and again.moves == job.plan.moves
    index = job.plan.move_ends[move - 1]
    assert list(again.segments.segments(0, index)) == list(job.plan.segments.segments(0, index))
    ticks = sum(s.n for s in again.segments.segments()), sum(s.n for s in job.plan.segments.segments())
    assert ticks[0] > ticks[1]  # the feeds after the boundary at half
