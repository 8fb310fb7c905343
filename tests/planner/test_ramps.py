"""Seed 004's ramp move and two-step arrival (planner/ramps.py), checked exactly."""

from __future__ import annotations

from fractions import Fraction

import pytest

from quadstep.kernel.cubic_chain import CubicChain
from quadstep.kernel.engine_model import predict
from quadstep.planner.ramps import ramp_distance, ramp_move, superpose, two_step_arrival
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.motion import CubicAxis

SIGMA = 1 << 31


@pytest.mark.parametrize(("n1", "n2", "r"), [(1, 0, 1), (10, 0, 1), (10, 5, 3), (100, 37, 11), (640, 1200, 7)])
def test_the_ramp_moves_exactly_the_seeds_p06_and_ends_at_rest(n1: int, n2: int, r: int) -> None:
    # p06 = (t01 + t12)(2·t01 + t12)·a1, with a1 = n1·r the acceleration after the first phase
    assert ramp_distance(ramp_move(n1, n2, r)) == (n1 + n2) * (2 * n1 + n2) * n1 * r


def s_curve(jerks: dict[int, int], n1: int = 400, n2: int = 300, cruise: int = 2000) -> list[CubicSegment]:
    def phase(n: int, sign: int) -> CubicSegment:
        return CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=sign * r) for a, r in sorted(jerks.items())))

    return [phase(n1, 1), CubicSegment(n=n2), phase(n1, -1), CubicSegment(n=cruise),
            phase(n1, -1), CubicSegment(n=n2), phase(n1, 1)]


def ideal_advance(segments: list[CubicSegment], axis: int) -> int:
    """The ideal's advance of one axis over a run, exactly (2^-31 step, signed)."""
    chain = CubicChain(3)
    total = 0
    for seg in segments:
        for step in chain.advance(seg):
            if step.axis == axis:
                s, n = step.start, seg.n
                total += step.start.direction * (n * s.i + n * (n - 1) // 2 * s.d + n * (n - 1) * (n - 2) // 6 * step.r)
    return total


def test_a_take_up_ramp_added_to_one_axis_leaves_the_others_step_for_step() -> None:
    run = s_curve({0: 900, 1: 400, 2: 1300})
    ramp = ramp_move(120, 50, 600)
    with_ramp = superpose(run, 1, start=1500, phases=ramp)
    before, after = predict(run, axis_count=3), predict(with_ramp, axis_count=3)
    for axis in (0, 2):
        assert (before.steps[before.steps[:, 1] == axis] == after.steps[after.steps[:, 1] == axis]).all()
    assert ideal_advance(with_ramp, 1) - ideal_advance(run, 1) == ramp_distance(ramp)
    assert abs((after.positions[1] - before.positions[1]) - ramp_distance(ramp) / SIGMA) <= 1
    assert after.motion_ticks == before.motion_ticks  # nothing paused
    chain = CubicChain(3)
    for seg in with_ramp:
        chain.advance(seg)  # every piece runnable where it stands
    assert all(a.at_rest for a in chain.axes)


def test_two_step_arrival_lands_at_rest_with_the_acceleration_step_the_notes_miss() -> None:
    t = Fraction(7)
    for v0, a0, p02 in [(Fraction(3), Fraction(1, 2), Fraction(60)), (Fraction(0), Fraction(0), Fraction(10)),
                        (Fraction(2), Fraction(-1, 3), Fraction(25))]:
        a1, a2 = two_step_arrival(v0, a0, p02, t)
        # acceleration linear from a0 to a1 over t, then to a2 over t: integrate exactly
        v1 = v0 + t * (a0 + a1) / 2
        v2 = v1 + t * (a1 + a2) / 2
        p = t * v0 + t * t * (a0 / 3 + a1 / 6) + t * v1 + t * t * (a1 / 3 + a2 / 6)
        assert v2 == 0 and p == p02
        assert (a2 == 0) == (p02 == t * (3 * v0 + a0 * t) / 3)
    _, a2 = two_step_arrival(Fraction(3), Fraction(0), 3 * t, t)  # p02 = t·(3·v0 + a0·t)/3 = 3t: a2 = 0
    assert a2 == 0
