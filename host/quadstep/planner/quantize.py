"""Path-speed profiles → integer per-axis speeds and the exact residual chain.

Per axis the planner tracks the ideal position `ideal2` (1/8192 step) and
the stepper position (steps), exactly as the firmware will. For a move whose
step target is T, the axis must travel M = |2·4096·T − ideal2| in 1/8192 step,
which is n·(v0 + vn) summed over the move's segments. Boundary speeds are the
profile's speed scaled to the axis and rounded to an integer: the entry and
exit speeds to nearest, interior ones down or up, whichever keeps the running
distance error smallest (error diffusion). The error at the end must stay
inside ±4096 (half a step) for the stepper, which rounds the ideal to the
nearest step, to land exactly on T; it is checked before anything is kept,
and the sub-step remainder is carried into the next move.
"""

from __future__ import annotations

import math

from ..kernel.fixed import N_MAX, D
from .profile import Profile
from .segments import SegmentArrays

TWO_D = 2 * D
V_LIMIT = D - 1  # never 4096: keeps clear of the one excluded residual case


class Quantizer:
    """Appends the segments of moves, dwells and stops to `out`, keeping the residual chain."""

    def __init__(self, out: SegmentArrays, start: tuple[int, ...]) -> None:
        self.out = out
        self.axis_count = out.axis_count
        self.position = list(start)
        self.ideal2 = [TWO_D * p for p in start]
        self.exit_speed = [0] * self.axis_count  # signed, of the last segment
        self.max_landing_error = 0  # largest |ideal − target| at a move end, 1/8192 step

    def dwell(self, ticks: int, line: int) -> None:
        """Segments with no axis: the machine stands still for `ticks` ticks."""
        zeros = [0] * self.axis_count
        while ticks > 0:
            n = min(ticks, N_MAX)
            self.out.append(n, 0, zeros, zeros, zeros, line)
            ticks -= n
        self.exit_speed = [0] * self.axis_count

    def move(
        self,
        target: tuple[int, ...],
        length: float,
        profile: Profile,
        line: int,
        continuous: bool = True,
    ) -> bool:
        """One straight move to the step `target` along the path-speed `profile`.

        Returns False, and appends nothing, if some axis would not land exactly on its
        target with this profile; the caller then tries another. `continuous` keeps an
        axis's entry speed equal to its previous exit speed when they differ by one unit.
        """
        ticks = profile.ticks
        count = len(ticks)
        axis_count = self.axis_count
        columns: list[list[int] | None] = [None] * axis_count
        direction = [1] * axis_count
        landing = 0
        for i in range(axis_count):
            if target[i] == self.position[i]:
                continue
            travel = TWO_D * target[i] - self.ideal2[i]
            sign = 1 if travel > 0 else -1
            direction[i] = sign
            v = self._axis_speeds(
                abs(travel),
                abs(travel) / (2.0 * length),
                sign,
                ticks,
                profile.speeds,
                i,
                continuous,
            )
            miss = abs(travel) - sum(n * (v[j] + v[j + 1]) for j, n in enumerate(ticks))
            if abs(miss) >= D:
                return False
            landing = max(landing, abs(miss))
            columns[i] = v
        self._emit(ticks, columns, direction, line)
        for i in range(axis_count):
            if self.position[i] != target[i]:
                raise AssertionError(
                    f"line {line}: axis {i} ends at step {self.position[i]}, not {target[i]}"
                )
        self.max_landing_error = max(self.max_landing_error, landing)
        self.exit_speed = [
            direction[i] * column[count] if column is not None else 0
            for i, column in enumerate(columns)
        ]
        return True

    def _axis_speeds(
        self,
        travel: int,
        scale: float,
        sign: int,
        ticks: tuple[int, ...],
        speeds: tuple[float, ...],
        axis: int,
        continuous: bool,
    ) -> list[int]:
        """Integer boundary speeds whose n·(v0+vn) sum to within the landing margin of `travel`."""
        count = len(ticks)
        ideal = [u * scale for u in speeds]
        first = min(V_LIMIT, round(ideal[0]))
        previous = self.exit_speed[axis] * sign
        if continuous and speeds[0] > 0.0 and previous > 0 and abs(previous - ideal[0]) < 1.0:
            first = previous  # straight on: keep the speed exactly continuous
        last = min(V_LIMIT, round(ideal[count])) if speeds[count] > 0.0 else 0
        if speeds[0] == 0.0:
            first = 0
        v = [first] + [0] * count
        v[count] = last
        # distance still to place if every interior speed were exact
        error = float(travel - ticks[0] * first - ticks[count - 1] * last)
        for j in range(1, count):
            error -= (ticks[j - 1] + ticks[j]) * ideal[j]
        for j in range(1, count):
            weight = ticks[j - 1] + ticks[j]
            low = math.floor(ideal[j])
            down = error - weight * (low - ideal[j])
            up = down - weight
            pick = low if abs(down) <= abs(up) else low + 1
            pick = min(max(pick, 0), V_LIMIT)
            v[j] = pick
            error -= weight * (pick - ideal[j])
        return v

    def _emit(
        self,
        ticks: tuple[int, ...],
        columns: list[list[int] | None],
        direction: list[int],
        line: int,
    ) -> None:
        axis_count = self.axis_count
        ideal2 = self.ideal2
        position = self.position
        for j, n in enumerate(ticks):
            bits = 0
            v0 = [0] * axis_count
            vn = [0] * axis_count
            r = [0] * axis_count
            for i in range(axis_count):
                col = columns[i]
                if col is None:
                    continue
                a, b = col[j], col[j + 1]
                if a == 0 and b == 0:
                    continue
                sign = direction[i]
                bits |= 1 << i
                if sign < 0:
                    bits |= 16 << i
                residual = sign * (ideal2[i] - TWO_D * position[i])
                travel = n * (a + b)
                v0[i], vn[i], r[i] = a, b, residual
                ideal2[i] += sign * travel
                position[i] += sign * ((residual + travel + D) // TWO_D)
            self.out.append(n, bits, v0, vn, r, line)
