"""The S-curve planner's closed-form run of a move's phases (planner/scurve_chain.py) against the
firmware's chain model (kernel/cubic_chain.py): on random phases — sets with direction changes, jerks
near their field's edge, phases longer than one segment, advances leaving 0 … 1 step — the run
refuses exactly what the chain refuses, and otherwise ends in the chain's state with its steps."""

from __future__ import annotations

import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

from quadstep.planner.scurve import _build
from quadstep.planner.scurve_chain import Phase, run_phases
from quadstep.kernel.fixed import CUBIC_N_MAX
from quadstep.kernel.fixed import SIGMA
from quadstep.kernel.cubic_chain import AxisState, CubicChain, CubicRefused
from quadstep.kernel.motion import CubicAxis

AXES = 3


@st.composite
def phases(draw: st.DrawFn) -> list[Phase]:
    out = []
    for _ in range(draw(st.integers(1, 7))):
        n = draw(st.sampled_from([0, 1, 2, 37, 800, CUBIC_N_MAX + 3]))
        jerk = {
            a: draw(st.sampled_from([0, 1, -1, 17, -300, 32767, -32768, 32768]))
            for a in range(AXES)
            if draw(st.booleans())
        }
        sets = {}
        for a in range(AXES):
            if draw(st.integers(0, 3)) == 0:
                speed = draw(st.sampled_from([0, 1, 1 << 20, SIGMA // 3, SIGMA - 1]))
                accel = draw(st.sampled_from([0, 5, -5, 1 << 16, -(1 << 16)]))
                direction = draw(st.sampled_from([1, -1]))
                sets[a] = CubicAxis(axis=a, speed=speed, accel=accel, direction=direction)
        out.append(Phase(n, jerk, sets))
    return out


@pytest.mark.slow
@settings(max_examples=400, deadline=None)
@given(phases(), st.lists(st.integers(-SIGMA // 2, SIGMA // 2 - 1), min_size=AXES, max_size=AXES))
def test_the_phase_run_is_the_chains(ph: list[Phase], residuals: list[int]) -> None:
    start = [AxisState(e=e) for e in residuals]
    run = run_phases(start, ph)
    chain = CubicChain(AXES, [AxisState(a.e, a.i, a.d, a.direction) for a in start])
    moved = [0] * AXES
    try:
        for segment in _build(ph):
            for step in chain.advance(segment):
                moved[step.axis] += step.start.direction * step.steps
    except (CubicRefused, ValueError):  # the firmware's refusal, or a field its message cannot hold
        assert run is None
        event("refused")
        return
    assert run is not None
    event("taken")
    assert run.end == chain.axes
    assert run.moved == moved
