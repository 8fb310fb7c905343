"""Checks of a planned job computed from its segments alone (what the firmware will execute).

Each check recomputes what it needs (ideal positions, stepper positions, speeds
in mm/s) independently of the planner's own bookkeeping, and returns a list of
problems (empty when the plan is good), so a failing test shows all of them.
"""

from __future__ import annotations

import math

import numpy as np

from quadstep.config import MachineConfig
from quadstep.planner.moves import CARRY_STEPS, MoveTable
from quadstep.planner.plan import Plan
from quadstep.kernel.fixed import D, N_MAX

# Per segment, a speed may differ from the exact plan by less than one 1/4096 step/tick at
# each end, so a speed change may exceed the acceleration limit by less than two quanta.
SPEED_QUANTA = 1
ACCEL_QUANTA = 2


def signed_speeds(plan: Plan) -> tuple[np.ndarray, np.ndarray]:
    """Per segment and axis, signed v0 and vn (negative when moving backwards), int64."""
    a = plan.segments.numpy()
    count = plan.segments.axis_count
    bits = a["axes"].astype(np.int64)
    active = np.stack([(bits >> i) & 1 for i in range(count)], axis=1).astype(bool)
    negative = np.stack([(bits >> (4 + i)) & 1 for i in range(count)], axis=1).astype(bool)
    sign = np.where(negative, -1, 1) * active
    return sign * a["v0"].astype(np.int64), sign * a["vn"].astype(np.int64)


def replay(plan: Plan) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Chain check: every residual equals the one the ideal and stepper positions imply.

    Returns problems, and the stepper and ideal positions (1/8192 step) after every
    segment, each (S+1, axes).
    """
    a = plan.segments.numpy()
    count = plan.segments.axis_count
    problems: list[str] = []
    ideal2 = [2 * D * p for p in plan.start]
    pos = list(plan.start)
    trail = np.empty((len(plan) + 1, count), dtype=np.int64)
    trail[0] = pos
    ideal_trail = np.empty((len(plan) + 1, count), dtype=np.int64)
    ideal_trail[0] = ideal2
    n_all = a["n"].tolist()
    bits_all = a["axes"].tolist()
    v0_all = a["v0"].tolist()
    vn_all = a["vn"].tolist()
    r_all = a["r"].tolist()
    for s, (n, bits) in enumerate(zip(n_all, bits_all)):
        if not 1 <= n <= N_MAX:
            problems.append(f"segment {s}: n = {n}")
        for i in range(count):
            if not bits & (1 << i):
                if bits & (16 << i):
                    problems.append(f"segment {s}: direction bit on still axis {i}")
                continue
            sign = -1 if bits & (16 << i) else 1
            v0, vn, r = v0_all[s][i], vn_all[s][i], r_all[s][i]
            if not (0 <= v0 <= D and 0 <= vn <= D and -D <= r <= D) or (r == D and v0 == vn == D):
                problems.append(f"segment {s} axis {i}: fields out of range v0={v0} vn={vn} r={r}")
            expected = sign * (ideal2[i] - 2 * D * pos[i])
            if r != expected:
                problems.append(f"segment {s} axis {i}: residual {r}, chain says {expected}")
            travel = n * (v0 + vn)
            ideal2[i] += sign * travel
            pos[i] += sign * ((r + travel + D) // (2 * D))
        trail[s + 1] = pos
        ideal_trail[s + 1] = ideal2
    return problems, trail, ideal_trail


def check_positions(plan: Plan, table: MoveTable, trail: np.ndarray) -> list[str]:
    """After every move, every axis stands exactly on the move's step target."""
    problems = []
    for k, end in enumerate(plan.move_ends):
        if tuple(int(x) for x in trail[end]) != table.target[k]:
            problems.append(f"move {k} (line {table.line[k]}): ends at {trail[end].tolist()}, target {table.target[k]}")
    if tuple(int(x) for x in trail[-1]) != plan.end:
        problems.append(f"job ends at {trail[-1].tolist()}, plan says {plan.end}")
    return problems


def quanta_per_tick(config: MachineConfig) -> tuple[np.ndarray, np.ndarray]:
    """Axis speed and acceleration limits in 1/4096 step per tick (and per tick²)."""
    hz = config.tick_hz
    vmax = np.array([a.max_speed * a.steps_per_mm / hz * D for a in config.axes])
    amax = np.array([a.max_accel * a.steps_per_mm / hz / hz * D for a in config.axes])
    return vmax, amax


def check_limits(plan: Plan) -> list[str]:
    """Axis speed ≤ limit + 1 quantum; per segment |vn − v0| ≤ limit·n + 2 quanta."""
    vmax, amax = quanta_per_tick(plan.config)
    v0, vn = signed_speeds(plan)
    n = plan.segments.numpy()["n"].astype(np.float64)
    problems = []
    over_speed = np.maximum(np.abs(v0), np.abs(vn)) > vmax + SPEED_QUANTA
    for s, i in zip(*np.nonzero(over_speed)):
        problems.append(f"segment {s} axis {i}: speed {max(abs(v0[s, i]), abs(vn[s, i]))} > {vmax[i]:.2f} quanta")
    change = np.abs(vn - v0)
    over_accel = change > amax[None, :] * n[:, None] + ACCEL_QUANTA
    for s, i in zip(*np.nonzero(over_accel)):
        problems.append(f"segment {s} axis {i}: speed change {change[s, i]} over {n[s]:.0f} ticks > limit")
    return problems


def check_continuity(plan: Plan, table: MoveTable) -> list[str]:
    """Speeds match exactly at every boundary inside a move, and the job ends at rest."""
    v0, vn = signed_speeds(plan)
    problems = []
    boundaries = set(plan.move_ends.tolist())
    boundaries.update(index for index, _ in plan.pauses)
    jumps = np.nonzero(np.any(vn[:-1] != v0[1:], axis=1))[0]
    for s in jumps.tolist():
        if s + 1 not in boundaries:
            jump = f"{vn[s].tolist()} → {v0[s + 1].tolist()}"
            problems.append(f"segments {s}→{s + 1}: speed jumps {jump} inside a move")
    if len(plan) and np.any(vn[-1] != 0):
        problems.append(f"job ends moving: {vn[-1].tolist()}")
    for index, line in plan.pauses:
        if index > 0 and np.any(vn[index - 1] != 0):
            problems.append(f"pause at line {line}: machine still moving {vn[index - 1].tolist()}")
    return problems


def junction_limit(table: MoveTable, k: int, config: MachineConfig) -> float:
    """GRBL's junction-deviation speed between move k−1 and move k, mm/s (reference formula)."""
    e1 = np.array(table.unit[k - 1])
    e2 = np.array(table.unit[k])
    cos_theta = -float(e1 @ e2)
    if cos_theta > 0.999999:
        return 0.0
    if cos_theta < -0.999999:
        return math.inf
    turn = e2 - e1
    turn /= np.linalg.norm(turn)
    accel = min(a.max_accel / abs(x) for a, x in zip(config.axes, turn) if abs(x) > 1e-12)
    sin_half = math.sqrt(0.5 * (1 - cos_theta))
    return math.sqrt(accel * config.junction_deviation * sin_half / (1 - sin_half))


def move_scale(table: MoveTable, k: int, ideal_at_start: np.ndarray) -> tuple[int, float]:
    """The fastest axis of move k and its quanta per mm/tick of path speed, as the planner scales it."""
    i = int(np.argmax(np.abs(table.delta[k])))
    travel = abs(2 * D * table.target[k][i] - int(ideal_at_start[i]))  # 1/8192 step
    return i, travel / (2.0 * table.length[k])


def check_junctions(plan: Plan, table: MoveTable, ideal_trail: np.ndarray) -> list[str]:
    """At each junction the path speed on both sides respects the cornering rule (within quantisation)."""
    config = plan.config
    hz = config.tick_hz
    v0, vn = signed_speeds(plan)
    ends = [0] + plan.move_ends.tolist()
    problems = []
    for k in range(1, len(table)):
        limit = junction_limit(table, k, config)
        i, scale = move_scale(table, k - 1, ideal_trail[ends[k - 1]])
        before = abs(vn[ends[k] - 1, i]) / scale * hz
        j, scale_next = move_scale(table, k, ideal_trail[ends[k]])
        after = abs(v0[ends[k], j]) / scale_next * hz
        for side, speed, quantum in (("before", before, hz / scale), ("after", after, hz / scale_next)):
            if speed > limit * (1 + 1e-9) + quantum:
                problems.append(f"junction {k} (line {table.line[k]}): {side} {speed:.4f} mm/s > rule {limit:.4f} mm/s")
    return problems


def check_stopping(plan: Plan, table: MoveTable, ideal_trail: np.ndarray) -> list[str]:
    """Nowhere is the path speed higher than the machine could stop from before the next stop.

    From any point, the squared speed it can shed is at most 2·A·(distance) summed over the
    rest of the current move and the moves after it (each with its own acceleration A)
    until the job ends, a dwell or a pause. Path speeds are read from each move's fastest
    axis: its speed over the distance it has to travel in the move (from the ideal
    position at the move's start to its target), as the planner scales it.
    """
    hz = plan.config.tick_hz
    a = plan.segments.numpy()
    n = a["n"].astype(np.float64)
    stop_before = {index for index, _ in table.stops}
    ends = plan.move_ends.tolist()
    problems = []
    budget_after = 0.0  # Σ 2·A·L (mm²/tick²) of the moves after the current one, up to the next stop
    for k in range(len(table) - 1, -1, -1):
        if k + 1 in stop_before or k == len(table) - 1:
            budget_after = 0.0
        first = ends[k - 1] if k else 0
        i = int(np.argmax(np.abs(table.delta[k])))
        v0 = a["v0"][first : ends[k], i].astype(np.float64)
        vn = a["vn"][first : ends[k], i].astype(np.float64)
        travel = abs(2 * D * table.target[k][i] - int(ideal_trail[first, i]))  # 1/8192 step
        scale = travel / (2.0 * table.length[k])  # quanta per mm/tick
        remaining = 0.0
        for s in range(ends[k] - 1, first - 1, -1):
            remaining += n[s] * (v0[s - first] + vn[s - first]) / 2.0 / scale  # mm
            speed = v0[s - first] / scale
            limit = math.sqrt(budget_after + 2.0 * table.accel[k] * remaining) + 2.0 / scale
            if speed > limit:
                problems.append(f"move {k} segment {s}: {speed * hz:.3f} mm/s cannot stop within {remaining:.4f} mm")
                break
        budget_after += 2.0 * table.accel[k] * table.length[k]
    return problems


def check_plan(plan: Plan, table: MoveTable) -> list[str]:
    problems, trail, ideal_trail = replay(plan)
    problems += check_positions(plan, table, trail)
    problems += check_stopping(plan, table, ideal_trail)
    problems += check_limits(plan)
    problems += check_continuity(plan, table)
    problems += check_junctions(plan, table, ideal_trail)
    return problems


def feed_problems(plan: Plan, table: MoveTable, feeds: list[float | None]) -> list[str]:
    """Each move's per-axis speeds stay within its feed along the path (mm/s), within one quantum."""
    config = plan.config
    v0, vn = signed_speeds(plan)
    problems = []
    start = 0
    for k, end in enumerate(plan.move_ends.tolist()):
        feed = feeds[k]
        if feed is not None:
            for i, axis in enumerate(config.axes):
                d = table.delta[k][i]
                if not d:
                    continue
                share = (abs(d) + CARRY_STEPS) / axis.steps_per_mm / table.length[k]
                cap = feed * share * axis.steps_per_mm / config.tick_hz * D + SPEED_QUANTA
                top = max(np.abs(v0[start:end, i]).max(), np.abs(vn[start:end, i]).max())
                if top > cap:
                    problems.append(f"move {k} axis {i}: {top} quanta > feed cap {cap:.2f}")
        start = end
    return problems
