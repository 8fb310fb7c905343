"""engine_model's HOLD prediction (docs/FIXED_POINT.md §8) against a literal integer loop.

The reference runs the segment's g/f loop for t0 ticks, then rescales its state and decelerates with
additions only, exactly as the firmware describes it; the model uses closed forms throughout.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

from quadstep.kernel.engine_model import advance, axis_hold, hold_shift, hold_step_change, predict, predict_hold, residual
from quadstep.protocol import Segment
from quadstep.kernel.fixed import D, DECEL_MAX, N_MAX
from quadstep.kernel.motion import AxisMove

BUDGET = 1 << 23


def literal_hold(n: int, mv: AxisMove, t0: int, decel: int) -> tuple[list[int], list[int], int]:
    """(ticks 1..t0 that step, hold ticks 1..J that step, J) by the loops, additions only."""
    c1 = mv.vn - mv.v0
    c2 = n * D
    c3 = c1 + 2 * n * mv.v0 - n * D
    h, b, db = n * mv.r + c3, c3 + 2 * c1 - c2, 2 * c1
    before = []
    for t in range(1, t0 + 1):
        if h >= 0:
            before.append(t)
            h += b
        else:
            h += 2 * c2 + b
        b += db
    k = 1
    while 2 * k * n <= N_MAX:
        k *= 2
    two_c2 = 2 * k * n * D
    d = -max(1, k * n * decel * 2 * D // 2**24)
    inc = (b - db + 2 * c2) * k  # the increment over the next tick, rescaled
    held = []
    if inc <= 0:
        return before, held, 0
    h, inc = h * k, inc + d
    j = 0
    while True:
        j += 1
        if h >= 0:
            held.append(j)
            h -= two_c2
            assert -BUDGET < h
        h += inc
        assert -BUDGET < h < BUDGET and -BUDGET < inc < BUDGET
        if inc <= 0:
            return before, held, j
        inc += d


def random_move(rng: random.Random, axis: int = 0) -> AxisMove:
    v0 = rng.choice([0, 1, D - 1, D, rng.randint(0, D)])
    vn = rng.choice([0, 1, D - 1, D, rng.randint(0, D)])
    r = rng.choice([-D, 0, D, rng.randint(-D, D)])
    if r == D and v0 == D and vn == D:
        r = D - 1
    return AxisMove(axis=axis, direction=rng.choice([1, -1]), v0=v0, vn=vn, r=r)


def test_shift_and_quantum() -> None:
    for n in range(1, N_MAX + 1):
        shift = hold_shift(n)
        assert n << shift <= N_MAX < n << (shift + 1)
    assert hold_step_change(N_MAX, DECEL_MAX) == -(N_MAX * DECEL_MAX // 2048)
    assert hold_step_change(512, 1) == -1  # below one quantum: one quantum
    assert hold_step_change(1000, 4000) == -1953  # ⌊2·1000·4096·4000 / 2^24⌋


def test_closed_form_equals_the_loop_at_random_moments() -> None:
    rng = random.Random(5150)
    for _ in range(1000):
        n = rng.choice([1, 2, 3, N_MAX, rng.randint(1, N_MAX), rng.randint(1, 50)])
        t0 = rng.choice([0, n - 1, rng.randrange(n)])
        mv = random_move(rng)
        decel = rng.choice([DECEL_MAX, rng.randint(1500, DECEL_MAX), rng.randint(1, DECEL_MAX)])
        if decel < 1500 and rng.random() < 0.8:
            decel = 1500  # keep most holds short
        before, held, stop = literal_hold(n, mv, t0, decel)
        hold = axis_hold(n, mv, t0, decel)
        assert hold.before == len(before)
        assert hold.stop == stop, (n, mv, t0, decel)
        if stop:
            s = hold.steps(np.arange(stop + 1))
            assert (np.flatnonzero(np.diff(s)) + 1).tolist() == held
            # Within half a step of the ideal deceleration throughout.
            j = np.arange(stop + 1, dtype=np.int64)
            ideal = hold.e0 + j * hold.i1 + hold.d * (j * (j - 1) // 2)
            assert np.all(np.abs(ideal[1:] - hold.w * s[1:]) <= hold.kn * D)


def test_a_long_hold_at_a_small_deceleration() -> None:
    mv = AxisMove(axis=0, direction=1, v0=D, vn=D, r=0)
    before, held, stop = literal_hold(N_MAX, mv, 100, 40)
    hold = axis_hold(N_MAX, mv, 100, 40)
    assert hold.d == -19  # ⌊1022·40 / 2^11⌋ quanta of 1/(2·1022·4096) step per tick²
    assert stop == hold.stop == -(-2 * N_MAX * D // 19)  # from a step per tick down to nothing
    p = predict_hold([Segment(n=N_MAX, axes=(mv,))], 100, [40, 40, 40, 40])
    assert p.positions[0] == len(before) + len(held)
    assert p.motion_ticks == 100 + stop
    assert p.steps[:, 0].tolist() == [100 + t for t in held]


def chain(rng: random.Random, count: int) -> list[Segment]:
    """Segments with continuous speeds and exactly carried residuals, as a planner makes them."""
    ideal = [0] * 4
    pos = [0] * 4
    speed = [0] * 4
    direction = [1] * 4
    out = []
    for i in range(count):
        n = rng.randint(1, N_MAX)
        moves = []
        for axis in range(4):
            if speed[axis] == 0:
                direction[axis] = rng.choice([1, -1])  # a reversal only from rest
            vn = 0 if i == count - 1 else max(0, min(D - 1, speed[axis] + rng.randint(-600, 600)))
            mv = AxisMove(axis=axis, direction=direction[axis], v0=speed[axis], vn=vn,
                          r=residual(ideal[axis], pos[axis], direction[axis]))
            ideal[axis], pos[axis] = advance(ideal[axis], pos[axis], n, mv)
            speed[axis] = vn
            moves.append(mv)
        out.append(Segment(n=n, axes=tuple(moves)))
    return out


def test_predict_hold_picks_the_running_segment_and_keeps_what_ran() -> None:
    rng = random.Random(8)
    segments = chain(rng, 12)
    starts = np.cumsum([0] + [s.n for s in segments])
    decels = [3000, 4000, 5000, 8191]
    for hold_tick in [0, int(starts[3]), int(starts[3]) + 1, int(starts[5]) - 1, int(starts[-1]) - 1]:
        p = predict_hold(segments, hold_tick, decels, positions=[10, 20, 30, 40], start_tick=0)
        index = int(np.searchsorted(starts, hold_tick, side="right")) - 1
        assert p.held == index
        assert p.hold_tick == hold_tick
        ran = predict(segments[:index], positions=[10, 20, 30, 40])
        seg = segments[index]
        t0 = hold_tick - int(starts[index])
        expect = list(ran.positions)
        last = 0
        for mv in seg.axes:
            before, held, stop = literal_hold(seg.n, mv, t0, decels[mv.axis])
            expect[mv.axis] += mv.direction * (len(before) + len(held))
            last = max(last, stop)
        assert p.positions == expect
        assert p.motion_ticks == hold_tick + last
        assert np.all(p.steps[:, 0] > hold_tick) and np.all(p.steps[:, 0] <= p.motion_ticks)
    at_end = predict_hold(segments, int(starts[-1]), decels)
    assert at_end.held is None and at_end.positions == predict(segments).positions
    with pytest.raises(ValueError):
        predict_hold(segments, int(starts[-1]) + 1, decels)
