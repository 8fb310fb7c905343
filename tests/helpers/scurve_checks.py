"""Checks of jerk-limited plans, read from the steps and the cubic stream alone (docs/PLANNER.md, "S-curves").

The acceleration is estimated from the stepper's positions every w ticks, a_m = (x(t+w) − 2x(t) + x(t−w))/w²
at t = m·w: the ideal's acceleration averaged with a triangle of half-width w. Between neighbouring estimates
it changes by at most J·w (the jerk limit J), plus 4/w² for the stepper's half step at each of the positions,
plus |Δv|/w for each speed set of size Δv (a corner, a landing correction) within the three windows.
"""

from __future__ import annotations

import numpy as np

from quadstep.config import MachineConfig
from quadstep.planner.moves import MoveTable
from quadstep.planner.plan import Plan
from quadstep.planner.scurve import START_JUMP
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.fixed import SIGMA
from quadstep.kernel.cubic_chain import CubicChain
from quadstep.protocol.segment import Segment

WINDOW = 640  # ticks: 20 ms at 32 kHz


def positions_every(steps: np.ndarray, axis: int, ticks: int, window: int) -> np.ndarray:
    """The stepper position of `axis` at ticks 0, w, 2w, … (steps: rows of tick, axis, direction)."""
    mine = steps[steps[:, 1] == axis]
    samples = np.arange(0, ticks + window, window)
    moved = np.concatenate([[0], np.cumsum(mine[:, 2])])
    return moved[np.searchsorted(mine[:, 0], samples, side="right")]


def acceleration_estimates(steps: np.ndarray, axis: int, ticks: int, window: int = WINDOW) -> np.ndarray:
    """a_m in steps per tick², m = 1 … (the window centres)."""
    x = positions_every(steps, axis, ticks, window).astype(np.float64)
    return (x[2:] - 2 * x[1:-1] + x[:-2]) / window**2


def speed_sets(plan: Plan) -> list[tuple[int, int, float]]:
    """(tick, axis, |speed change| in steps per tick) at every state set of the plan's cubic segments."""
    chain = CubicChain(plan.segments.axis_count)
    tick = 0
    out = []
    for seg in plan.segments.segments():
        if isinstance(seg, CubicSegment):
            for m in seg.axes:
                if m.speed is not None:
                    state = chain.axes[m.axis]
                    out.append((tick, m.axis, abs(m.speed * m.direction - state.i * state.direction) / SIGMA))
            chain.advance(seg)
        else:  # the plan's anchor: one tick at rest that puts the ideal on the stepper
            assert all(m.v0 == m.vn == m.r == 0 for m in seg.axes)
            chain.follow_quadratic(seg, {m.axis: 0 for m in seg.axes})
        tick += seg.n
    return out


def jerk_violations(steps: np.ndarray, plan: Plan, config: MachineConfig, window: int = WINDOW) -> list[str]:
    """Every pair of neighbouring windows whose acceleration estimate changes by more than the bound above,
    and, per axis, the largest change seen against the jerk term (to show the check is not vacuous)."""
    problems = []
    ticks = plan.duration_ticks
    sets = speed_sets(plan)
    hz = float(config.tick_hz)
    for axis, cfg in enumerate(config.axes):
        if cfg.max_jerk is None:
            continue
        jerk = cfg.max_jerk * cfg.steps_per_mm / hz**3  # steps per tick³
        a = acceleration_estimates(steps, axis, ticks, window)
        jumps = np.zeros(len(a) + 3)
        for tick, k, size in sets:
            if k == axis:
                jumps[tick // window] += size
        for m in range(len(a) - 1):
            # estimates m and m+1 are centred at (m+1)·w and (m+2)·w: together they read ticks m·w … (m+3)·w
            near = jumps[m:m + 3].sum()
            bound = jerk * window + 4 / window**2 + near / window
            change = abs(a[m + 1] - a[m])
            if change > bound:
                problems.append(f"axis {axis}: acceleration changes by {change:.3g} between windows at tick "
                                f"{(m + 1) * window}, more than {bound:.3g} step/tick²")
    return problems


def largest_jerk_phase_change(steps: np.ndarray, plan: Plan, axis: int, window: int = WINDOW) -> tuple[float, float]:
    """The largest change of the acceleration estimate between neighbouring windows whose speed sets are
    small (their term in the bound below a tenth of the jerk term), and that jerk term J·w (step/tick²)."""
    cfg = plan.config.axes[axis]
    assert cfg.max_jerk is not None
    jerk_term = cfg.max_jerk * cfg.steps_per_mm / float(plan.config.tick_hz) ** 3 * window
    a = acceleration_estimates(steps, axis, plan.duration_ticks, window)
    jumps = np.zeros(len(a) + 3)
    for tick, k, size in speed_sets(plan):
        if k == axis:
            jumps[tick // window] += size
    quiet = [abs(a[m + 1] - a[m]) for m in range(len(a) - 1) if jumps[m:m + 3].sum() / window < 0.1 * jerk_term]
    return max(quiet, default=0.0), jerk_term


def check_scurve_plan(plan: Plan, table: MoveTable) -> list[str]:
    """From the cubic stream alone: every move lands on its target with the acceleration back at 0, the job
    rests at its stops and end, and per axis the speed, acceleration and jerk stay within the limits plus
    their quantisation (docs/PLANNER.md, "S-curves"): speed by the landing corrections (START_JUMP), the
    acceleration by half a jerk quantum per tick of the ramp that built it, the jerk by half a quantum."""
    config = plan.config
    hz = float(config.tick_hz)
    vmax = [a.max_speed * a.steps_per_mm / hz * SIGMA for a in config.axes]
    amax = [a.max_accel * a.steps_per_mm / hz**2 * SIGMA for a in config.axes]
    jmax = [(a.max_jerk or float("inf")) * a.steps_per_mm / hz**3 * SIGMA for a in config.axes]
    problems: list[str] = []
    chain = CubicChain(plan.segments.axis_count)
    position = list(plan.start)
    built = [0] * len(position)  # ticks since each axis's acceleration was last 0
    ends = {e: k for k, e in enumerate(plan.move_ends)}
    rests = {i for i, _ in plan.pauses}
    for i, seg in enumerate(plan.segments.segments()):
        if i in rests and not all(a.at_rest for a in chain.axes):
            problems.append(f"segment {i}: a pause while moving")
        if isinstance(seg, Segment):
            chain.follow_quadratic(seg, {m.axis: 0 for m in seg.axes})
        else:
            for m in seg.axes:
                if m.jerk is not None and abs(m.jerk) > jmax[m.axis] + 0.5:
                    problems.append(f"segment {i}: axis {m.axis} jerk {m.jerk} over {jmax[m.axis]:.1f}")
            for step in chain.advance(seg):
                position[step.axis] += step.start.direction * step.steps
        for axis, a in enumerate(chain.axes):
            built[axis] = 0 if a.d == 0 else built[axis] + seg.n
            if a.i > vmax[axis] + START_JUMP + 1:
                problems.append(f"segment {i}: axis {axis} speed {a.i / SIGMA:.5f} over {vmax[axis] / SIGMA:.5f}")
            if abs(a.d) > amax[axis] * (1 + 1e-9) + built[axis] / 2:
                problems.append(f"segment {i}: axis {axis} acceleration {a.d} over {amax[axis]:.0f}")
        if i + 1 in ends:
            k = ends[i + 1]
            if tuple(position) != table.target[k]:
                problems.append(f"move {k}: ends at {position}, target {table.target[k]}")
            if any(a.d for a in chain.axes):
                problems.append(f"move {k}: acceleration not 0 at its end")
    if not all(a.at_rest for a in chain.axes):
        problems.append("the plan does not end at rest")
    if tuple(position) != plan.end:
        problems.append(f"the plan ends at {position}, not {plan.end}")
    return problems
