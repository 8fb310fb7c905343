"""engine_model (closed form of PROTOCOL.md §8) against a literal integer g/f loop."""

from __future__ import annotations

import random
from typing import Literal

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from quadstep.kernel.engine_model import advance, predict, residual, segment_steps, step_ticks, steps_by_tick
from quadstep.protocol import Segment
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove

LIMIT = 2 * N_MAX * D + 3 * D  # no per-tick value may leave ±LIMIT (it is < 2^23)


def gf_loop(n: int, v0: int, vn: int, r: int) -> list[int]:
    """The firmware's per-tick loop in the h/B/dA form, additions only: ticks (1..n) that step."""
    c1 = vn - v0
    c2 = n * D
    c3 = c1 + 2 * n * v0 - n * D
    h = n * r + c3
    b = c3 + 2 * c1 - c2
    da = 2 * c1
    ticks = []
    for t in range(1, n + 1):
        assert -LIMIT <= h <= LIMIT and -LIMIT <= b <= LIMIT
        if h >= 0:
            ticks.append(t)
            h += b
        else:
            h += 2 * c2
            assert h <= LIMIT
            h += b
        assert -LIMIT <= h <= LIMIT
        b += da
    return ticks


def random_move(rng: random.Random, axis: int = 0) -> AxisMove:
    pick = rng.choice
    v0 = pick([0, 1, D - 1, D, rng.randint(0, D)])
    vn = pick([0, 1, D - 1, D, rng.randint(0, D)])
    r = pick([-D, -D + 1, 0, D - 1, D, rng.randint(-D, D)])
    if r == D and v0 == D and vn == D:
        r = D - 1
    return AxisMove(axis=axis, direction=pick([1, -1]), v0=v0, vn=vn, r=r)


def random_n(rng: random.Random) -> int:
    return rng.choice([1, 2, 3, N_MAX, rng.randint(1, N_MAX), rng.randint(1, 40)])


def test_closed_form_equals_the_loop_on_random_segments() -> None:
    rng = random.Random(20240611)
    for _ in range(2500):
        n, mv = random_n(rng), random_move(rng)
        expected = gf_loop(n, mv.v0, mv.vn, mv.r)
        assert step_ticks(n, mv).tolist() == expected, (n, mv)
        assert segment_steps(n, mv) == len(expected)


@settings(max_examples=300, deadline=None)
@given(
    n=st.integers(1, N_MAX),
    v0=st.integers(0, D),
    vn=st.integers(0, D),
    r=st.integers(-D, D),
)
def test_closed_form_equals_the_loop_hypothesis(n: int, v0: int, vn: int, r: int) -> None:
    if r == D and v0 == D and vn == D:
        return
    mv = AxisMove(axis=0, direction=1, v0=v0, vn=vn, r=r)
    assert step_ticks(n, mv).tolist() == gf_loop(n, v0, vn, r)


@pytest.mark.parametrize("n", [1, 2, 511, N_MAX])
def test_extreme_corners(n: int) -> None:
    for v0 in (0, 1, D - 1, D):
        for vn in (0, 1, D - 1, D):
            for r in (-D, -D + 1, 0, D - 1, D):
                if r == D and v0 == D and vn == D:
                    continue
                mv = AxisMove(axis=0, direction=-1, v0=v0, vn=vn, r=r)
                assert step_ticks(n, mv).tolist() == gf_loop(n, v0, vn, r)


def test_steps_stay_within_half_a_step_of_the_ideal() -> None:
    rng = random.Random(7)
    for _ in range(500):
        n, mv = random_n(rng), random_move(rng)
        t = np.arange(n + 1, dtype=np.int64)
        s = steps_by_tick(n, mv, t)
        ideal_2nd = n * mv.r + (mv.vn - mv.v0) * t * t + 2 * n * mv.v0 * t  # ideal × 2nD
        assert np.all(np.abs(ideal_2nd - 2 * n * D * s) <= n * D)
        assert np.all(np.diff(s) >= 0) and np.all(np.diff(s) <= 1)


def test_chained_residuals_never_drift() -> None:
    """Carrying the ideal in 1/8192 step and r = residual(...) keeps a long chain within ½ step."""
    rng = random.Random(99)
    ideal2, position = 0, 0
    for _ in range(3000):
        n = random_n(rng)
        direction: Literal[1, -1] = rng.choice([1, -1])
        v0, vn = rng.randint(0, D), rng.randint(0, D)
        r = residual(ideal2, position, direction)
        assert -D <= r <= D
        if r == D and v0 == D and vn == D:
            vn = D - 1
        mv = AxisMove(axis=0, direction=direction, v0=v0, vn=vn, r=r)
        looped = gf_loop(n, v0, vn, r)
        ideal2, position = advance(ideal2, position, n, mv)
        assert abs(ideal2 - 2 * D * position) <= D
        assert segment_steps(n, mv) == len(looped)


def test_predict_orders_steps_and_tracks_positions() -> None:
    rng = random.Random(3)
    segments = []
    for _ in range(60):
        axes = sorted(rng.sample(range(4), rng.randint(0, 4)))
        segments.append(Segment(n=random_n(rng), axes=tuple(random_move(rng, a) for a in axes)))
    start = [5, -7, 0, 100]
    p = predict(segments, positions=start, start_tick=1000)
    rows = []
    tick = 1000
    pos = list(start)
    for seg in segments:
        for mv in seg.axes:
            for t in gf_loop(seg.n, mv.v0, mv.vn, mv.r):
                rows.append((tick + t, mv.axis, mv.direction))
            pos[mv.axis] += mv.direction * len(gf_loop(seg.n, mv.v0, mv.vn, mv.r))
        tick += seg.n
    rows.sort()
    assert p.steps.tolist() == [list(r) for r in rows]
    assert p.positions == pos
    assert p.motion_ticks == sum(s.n for s in segments)
    assert p.segments == len(segments)
    assert sum(p.per_axis_steps) == len(rows)


def test_predict_of_nothing() -> None:
    p = predict([])
    assert p.steps.shape == (0, 3) and p.positions == [0, 0, 0, 0] and p.motion_ticks == 0
