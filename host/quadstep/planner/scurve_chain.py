"""A move's phases run through the firmware's cubic chain in plain integers (docs/CUBIC.md §2–3).

The planner tries several versions of each move before one lands; running every version through the
kernel's CubicChain (kernel/cubic_chain.py: one message model per segment) is what made S-curve
planning slow. Here each phase is checked and advanced in closed form, with the checks the firmware
makes on the segments the phases become (planner/scurve.py `_build`: a phase longer than CUBIC_N_MAX
ticks is several segments of the same cubic, so its ends decide the same checks), and the segments
are built once, for the version that lands.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..kernel.cubic_chain import AxisState, extreme_in_range
from ..kernel.fixed import CUBIC_ACCEL_LIMIT, CUBIC_N_MAX, CUBIC_SHIFT, HALF, JERK_LIMIT, SIGMA
from ..kernel.motion import CubicAxis


@dataclass
class Phase:
    """Ticks of one jerk per axis (none: 0), after the speed sets at its start."""

    n: int
    jerk: dict[int, int]
    sets: dict[int, CubicAxis]


State = tuple[int, int, int, int]  # e, i, d, direction: an axis of the chain


@dataclass
class PhaseRun:
    """Each axis's state at every phase's start and after the last (`states[len(phases)]`), the
    steps each made (signed), and its highest advance at a segment's end."""

    states: list[list[State]]
    moved: list[int]
    peak: list[int]

    @property
    def end(self) -> list[AxisState]:
        return [
            AxisState(e, i, d, 1 if direction > 0 else -1) for e, i, d, direction in self.states[-1]
        ]


def _set_fits(s: CubicAxis) -> bool:
    """What the message's own fields allow (the model checks these when it is built)."""
    return s.speed is None or (0 <= s.speed < 1 << 31 and abs(s.accel) < CUBIC_ACCEL_LIMIT)


def run_phases(start: list[AxisState], phases: list[Phase]) -> PhaseRun | None:
    """The chain through `phases` from `start` (not changed); None where the firmware would refuse
    a segment (or a field would not fit its message)."""
    axes: list[State] = [(a.e, a.i, a.d, a.direction) for a in start]
    moved = [0] * len(axes)
    peak = [0] * len(axes)
    states = [axes]
    pending: dict[int, CubicAxis] = {}  # sets of an empty phase go to the next one
    for ph in phases:
        sets = {**pending, **ph.sets} if pending else ph.sets
        if ph.n == 0:
            pending = sets
            states.append(axes)
            continue
        pending = {}
        axes = list(axes)
        n, jerks = ph.n, ph.jerk
        c2, c3 = n * (n - 1) // 2, n * (n - 1) * (n - 2) // 6
        for axis, (e, i, d, direction) in enumerate(axes):
            r = jerks.get(axis, 0)
            s = sets.get(axis)
            if s is not None and s.speed is not None:
                if not _set_fits(s):
                    return None
                if s.direction != direction:
                    e, direction = -e, s.direction
                i, d = s.speed, s.accel
                axes[axis] = (e, i, d, direction)
            if not (i or d or r):
                continue
            d_end = d + n * r
            i_end = i + n * d + c2 * r  # the advance after the phase: I(n + 1)
            if not (
                -JERK_LIMIT <= r < JERK_LIMIT
                and -CUBIC_ACCEL_LIMIT < d_end < CUBIC_ACCEL_LIMIT
                and 0 <= i <= SIGMA
                and 0 <= i_end - d_end + r <= SIGMA  # I(n)
                and extreme_in_range(i, d, r, n)
            ):
                return None
            total = e + n * i + c2 * d + c3 * r + HALF
            moved[axis] += direction * (total >> CUBIC_SHIFT)
            axes[axis] = ((total & (SIGMA - 1)) - HALF, i_end, d_end, direction)
            # the segments' ends: the phase's own, and where a long one is split
            top = i_end if n <= CUBIC_N_MAX else max(i_end, _split_peak(i, d, r, n))
            if top > peak[axis]:
                peak[axis] = top
        states.append(axes)
    return PhaseRun(states, moved, peak)


def _split_peak(i: int, d: int, r: int, n: int) -> int:
    """The highest advance at the inner ends of a phase split into CUBIC_N_MAX-tick segments."""
    top = 0
    for t in range(CUBIC_N_MAX, n, CUBIC_N_MAX):
        top = max(top, i + t * d + t * (t - 1) // 2 * r)
    return top


__all__ = ["Phase", "PhaseRun", "run_phases"]
