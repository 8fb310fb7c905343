"""Look-ahead: the speed at every junction between moves.

Corners follow GRBL's junction-deviation rule: the speed at which a circle of
radius `junction_deviation`·sin(θ/2)/(1−sin(θ/2)) tangent to both moves could be
followed at the junction's acceleration limit. A move under G64 P uses P as its
deviation, one under G61 stops at its corner. A backward pass then lowers
every junction so the machine can still stop by the end of the job (or the
next stop), and a forward pass so each speed can be reached from the one
before: within √(v² + 2aL) at constant acceleration, within the jerk-limited ramp's reach where the
move has a jerk limit (planner/jerk.py). Speeds in mm/tick.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..config import MachineConfig
from .jerk import reachable_speed
from .moves import MoveTable
from .program import JobError, SetOutputs

# An axis whose backlash is taken up (docs/BACKLASH.md) and that turns around sharply at a junction
# — moving along both moves by more than this share of the path — stops there: the take-up then runs
# at rest, where it costs no acceleration. (Shallow reversals, as on an arc's chords, take it up on
# the move.)
SHARP_REVERSAL = 0.25
# A take-up of at most this many steps does not stop a sharp reversal: it runs on the move, with the
# acceleration the plan leaves, and the carriage is at most that far behind the plan meanwhile —
# the size of the steppers' own rounding. (A larger one would leave it up to the whole backlash
# behind.)
SUPERPOSED_TAKEUP_STEPS = 1

# Ramps are planned at this fraction of each move's acceleration (and jerk) limit; the
# rest is room for rounding every phase to whole ticks (docs/PLANNER.md).
PLAN_ACCEL_FRACTION = 0.98


def _junction_speed(table: MoveTable, k: int, config: MachineConfig, amax: list[float]) -> float:
    """Highest speed at the junction between move k−1 and move k (mm/tick)."""
    e1 = table.unit[k - 1]
    e2 = table.unit[k]
    cos_theta = -sum(a * b for a, b in zip(e1, e2))
    cap = min(table.max_speed[k - 1], table.max_speed[k])
    own = table.deviation[k]  # G64 P, or G61's 0
    deviation = own if own is not None else config.junction_deviation
    if cos_theta > 0.999999 or deviation == 0.0:
        return 0.0  # full reversal, or exact stop (G61)
    for i, axis in enumerate(config.axes):
        if (
            axis.backlash_steps > SUPERPOSED_TAKEUP_STEPS
            and e1[i] * e2[i] < 0
            and min(abs(e1[i]), abs(e2[i])) > SHARP_REVERSAL
        ):
            return 0.0  # a sharp reversal of an axis with backlash: its take-up at rest
    if cos_theta < -0.999999:
        return cap  # straight on
    turn = [b - a for a, b in zip(e1, e2)]
    norm = math.sqrt(sum(x * x for x in turn))
    # a move's own lower limit, if it has one
    accel = min(table.accel_cap[k - 1], table.accel_cap[k])
    for i, x in enumerate(turn):
        if abs(x) > 1e-12:
            accel = min(accel, amax[i] * norm / abs(x))
    sin_half = math.sqrt(0.5 * (1.0 - cos_theta))
    return min(cap, math.sqrt(accel * deviation * sin_half / (1.0 - sin_half)))


def junction_speeds(table: MoveTable, config: MachineConfig, entry: float = 0.0) -> list[float]:
    """Entry speed of every move, plus the exit speed of the last (always 0): len(table) + 1 values.

    `entry` pins the first move's entry speed (a plan that goes on from another, moving: a feed
    override): the junctions after it are raised where it could not slow down to them otherwise. The
    plan it goes on from slowed down from there to its stops, so the raised speeds stay under that
    plan's and inside the limits."""
    count = len(table)
    hz = float(config.tick_hz)
    amax = [a.max_accel / (hz * hz) for a in config.axes]
    stopped = {
        index
        for index, item in table.stops
        if not (isinstance(item, SetOutputs) and config.spindle.laser)
    }
    limit = [0.0] * (count + 1)
    limit[0] = entry
    for k in range(1, count):
        if k not in stopped:
            limit[k] = _junction_speed(table, k, config, amax)
    accel = [a * PLAN_ACCEL_FRACTION for a in table.accel]
    jerk = [j * PLAN_ACCEL_FRACTION for j in table.jerk] if table.jerk else [math.inf] * count
    # backward: every entry speed must be able to slow to the next one within the move
    for k in range(count - 1, 0 if entry else -1, -1):
        reachable = reachable_speed(limit[k + 1], table.length[k], accel[k], jerk[k])
        if reachable < limit[k]:
            limit[k] = reachable
    # forward: and be reachable from the one before
    for k in range(count):
        reachable = reachable_speed(limit[k], table.length[k], accel[k], jerk[k])
        if reachable < limit[k + 1]:
            limit[k + 1] = reachable
        if entry:
            least = math.sqrt(max(0.0, limit[k] ** 2 - 2.0 * accel[k] * table.length[k]))
            if least > 1e-6 * limit[k] and least > limit[k + 1]:
                if k + 1 == count or k + 1 in stopped:
                    raise JobError(
                        f"line {table.line[k]}: cannot slow down to the stop from the pinned speed"
                    )
                limit[k + 1] = least
    return limit


def settled_moves(junctions: Sequence[float], moves: int) -> int:
    """The moves that more moves after the last leave as planned (`junctions`: each move's entry
    speed, then 0): those before the last stretch whose entry speeds fall all the way to the stop at
    the end. Further back an entry speed is no higher than the next one, so the backward pass from
    the end does not limit it, and more moves after the end, which can only raise that pass, change
    nothing before it."""
    move = moves - 1
    while move > 0 and junctions[move] > junctions[move + 1]:
        move -= 1
    return max(move, 0)
