"""Jerk-limited plans: every move an S-curve of exact cubic segments (docs/PLANNER.md, "S-curves").

Per move the path speed goes v0 → vc in a ramp (jerk +J, 0, −J), cruises at vc, and goes vc → v1 in
a ramp; the acceleration is 0 at both ends of every ramp, so at every junction. The phases are whole
ticks (planner/jerk.py rounds them up), vc is then solved so the path's length is covered exactly.
Per axis the jerk of each ramp is rounded once, R = round(Σ·j); every state after that is the
firmware's own exact integer chain (kernel/cubic_chain.py): the ramp's symmetric phases bring the
acceleration back to exactly 0, a state set at the start of a ramp that ends at rest makes the speed
end at exactly 0, and the cruise's speed, set where it begins, lands each axis on its target after
its ramps' rounded jerks, so the axes keep the path's proportion; a move without a cruise lands by
its ramps' jerks and speed sets spread over the move. Corners set each axis's speed as the
junction-deviation rule allows (its acceleration is 0 on both sides).
"""

from __future__ import annotations

import math
from functools import lru_cache

from ..config import MachineConfig
from ..kernel.cubic_chain import AxisState, CubicChain
from ..kernel.fixed import CUBIC_N_MAX, SIGMA
from ..kernel.motion import AxisMove, CubicAxis, Direction
from ..protocol.cubic import CubicSegment
from ..protocol.segment import Segment
from .moves import MoveTable
from .program import JobError
from .scurve_chain import Phase as _Phase
from .scurve_chain import PhaseRun, State, run_phases
from .scurve_profile import PROFILE_FRACTION, Profile, whole_tick_profile
from .scurve_state import ScurveState
from .stream import Stream

# a junction keeps an axis's speed without a set when it is this close (2^-16 step/tick)
SPEED_KEPT = 1 << 15
# a move's ideal may end this far from its target (the stepper is on it; the next move starts from
# the exact ideal)
LAND_SLACK = SIGMA * 9 // 20
# a correction on a cruise may always be this large (2^-12 step per tick), or as large as the speed
# the ramps' rounded jerks can miss (half a jerk quantum over their phases)
JUMP_LIMIT = 1 << 19
START_JUMP = 1 << 21  # a correction at a move's start (a junction): at most 2^-10 step per tick


class ScurvePlanner:
    """Moves in order → cubic segments, with the firmware's chain carried exactly from move to
    move."""

    def __init__(self, config: MachineConfig, start: tuple[int, ...], label: str) -> None:
        self.config = config
        self.count = len(config.axes)
        self.label = label
        self.chain = CubicChain(self.count)
        self.position = list(start)
        self.out = Stream([], axes=self.count)
        self.peak = [0] * self.count  # highest advance per tick, 2^-31 step
        self.max_landing = 0  # largest |ideal − target| at a move end, 2^-31 step
        self.corrections = 0  # moves landed by a speed set on the cruise
        self.steady_moves = 0  # moves no whole-tick S-curve landed: at a constant speed instead
        self.pauses: list[tuple[int, int]] = []  # (segment index, line) before which to wait
        self.profiles: list[Profile] = []  # each move's, as planned
        self.speed = 0.0  # the path speed the last move ended at
        hz = float(config.tick_hz)
        self.speed_limit = [a.max_speed * a.steps_per_mm / hz * SIGMA for a in config.axes]
        self.accel_limit = [a.max_accel * a.steps_per_mm / hz**2 * SIGMA for a in config.axes]
        self.jerk_limit = [
            (a.max_jerk or math.inf) * a.steps_per_mm / hz**3 * SIGMA for a in config.axes
        ]
        # the firmware's chain may hold any residual from before: a 1-tick quadratic at rest puts it
        # on the ideal
        self.out.add(
            Segment(
                n=1,
                axes=tuple(
                    AxisMove(axis=a, direction=1, v0=0, vn=0, r=0) for a in range(self.count)
                ),
            ),
            0,
            0,
        )

    def state(self, move: int, distance_mm: float) -> ScurveState:
        """This planner as it is, where move `move` begins (`distance_mm`: the moves' length)."""
        return ScurveState(
            move,
            len(self.out),
            self.chain.copy(),
            tuple(self.position),
            self.speed,
            tuple(self.peak),
            self.max_landing,
            self.corrections,
            distance_mm,
        )

    @classmethod
    def resume(
        cls, config: MachineConfig, state: ScurveState, out: Stream, label: str
    ) -> ScurvePlanner:
        """A planner that goes on from `state`, adding to `out` (the plan's segments before it)."""
        planner = cls(config, state.position, label)
        planner.chain = state.chain.copy()
        planner.out = out
        planner.speed = state.speed
        planner.peak = list(state.peak)
        planner.max_landing = state.max_landing
        planner.corrections = state.corrections
        return planner

    # --- one move ---------------------------------------------------------------------------------

    def move(self, table: MoveTable, k: int, entry: list[float]) -> None:
        """Plan move k, from the speed the move before ended at, to at most the look-ahead's
        junction speed (capped a little under the speed limits too, as the profiles are: room for
        the landing corrections)."""
        cap = PROFILE_FRACTION * min(
            table.max_speed[k], table.max_speed[k + 1] if k + 1 < len(table) else math.inf
        )
        v0, v1 = min(self.speed, entry[k]), min(entry[k + 1], cap)
        line = table.line[k]
        vmax = table.max_speed[k]
        steady = max(v0, v1)  # the speed to land at without a profile (the last resort)
        for attempt in range(8):
            try:
                profile = whole_tick_profile(
                    table.length[k],
                    v0,
                    v1,
                    max(vmax * PROFILE_FRACTION, v0, v1),
                    table.accel[k] * PROFILE_FRACTION,
                    table.jerk[k] * PROFILE_FRACTION,
                )
            except ValueError:
                break
            landed = self._segments(table, k, profile)
            if landed is not None:
                self._emit(*landed, line)
                self.profiles.append(profile)
                self.speed = profile.v1
                return
            steady = table.length[k] / profile.ticks
            vmax = profile.vc * 0.97  # no cruise to land on, or one too short: make a longer one
        self._steady(table, k, steady or table.max_speed[k] * PROFILE_FRACTION, v1 == 0)
        self.profiles.append(Profile(self.speed, self.speed, self.speed, 0, 0, 0, 0, 0))

    def _steady(self, table: MoveTable, k: int, speed: float, to_rest: bool) -> None:
        """The move at one constant speed per axis, set where it begins, when no whole-tick
        S-curve lands it: each axis's speed is the distance its ideal has left over the move's
        whole ticks, so it lands within half a tick's advance of its target, whatever came
        before; the cost is a speed step at both ends. It ends at rest when the move must."""
        target = table.target[k]
        ticks = max(1, math.ceil(table.length[k] / speed))
        remaining: dict[int, tuple[Direction, int]] = {}
        for axis, state in enumerate(self.chain.axes):
            if not table.delta[k][axis]:
                continue
            direction: Direction = 1 if table.delta[k][axis] > 0 else -1
            ahead = state.e if state.direction == direction else -state.e
            left = (target[axis] - self.position[axis]) * direction * SIGMA - ahead
            remaining[axis] = direction, max(0, left)
            ticks = max(ticks, math.ceil(left / min(self.speed_limit[axis], SIGMA)))
        sets = []
        for axis, state in enumerate(self.chain.axes):
            if axis in remaining:
                direction, left = remaining[axis]
                sets.append(CubicAxis(axis=axis, speed=round(left / ticks), direction=direction))
            elif not state.at_rest:
                sets.append(CubicAxis(axis=axis, speed=0, direction=state.direction))
        phases = [_Phase(ticks, {}, {a.axis: a for a in sets})]
        if to_rest:
            stop = {a.axis: CubicAxis(axis=a.axis, speed=0, direction=a.direction) for a in sets}
            phases.append(_Phase(1, {}, stop))
        run = run_phases(self.chain.axes, phases)
        assert run is not None, "a steady speed within 0 … 1 step per tick is always taken"
        self._emit(phases, run, table.line[k])
        self.steady_moves += 1
        self.speed = 0.0 if to_rest else table.length[k] / ticks

    def _segments(
        self, table: MoveTable, k: int, p: Profile
    ) -> tuple[list[_Phase], PhaseRun] | None:
        """The move's phases, landing every axis on its target, and the chain through them; None
        when they cannot."""
        target, delta = table.target[k], table.delta[k]
        shaped = self._shape(table, k, p)
        if shaped is None:
            return None
        phases, exits = shaped
        built = self._built(phases, target)
        if built is None:
            return None
        if self._retune_starts(p, phases, built[1]):
            built = self._built(phases, target)
            if built is None:
                return None
        if self._retune_stops(p, phases, built[1], exits):
            built = self._built(phases, target)
            if built is None:
                return None
        corrections = self.corrections
        if not self._land(p, phases, *built, delta):
            return None
        if self.corrections != corrections:  # speed sets added: run the phases again
            built = self._built(phases, target)
        if built is None or any(abs(m) > LAND_SLACK for m in built[1].values()):
            return None
        return phases, built[0]

    def _shape(self, table: MoveTable, k: int, p: Profile) -> tuple[list[_Phase], list[int]] | None:
        """The profile's seven phases with each axis's share of its jerks and speed sets, and each
        axis's exit speed; None when a last ramp would have to begin below rest."""
        delta, length = table.delta[k], table.length[k]
        share = [abs(d) / length * SIGMA for d in delta]  # 2^-31 step per mm of path
        kd = p.n1d * (p.n1d + p.n2d)
        phases = [
            _Phase(p.n1a, {}, {}),
            _Phase(p.n2a, {}, {}),
            _Phase(p.n1a, {}, {}),
            _Phase(p.nc, {}, {}),
            _Phase(p.n1d, {}, {}),
            _Phase(p.n2d, {}, {}),
            _Phase(p.n1d, {}, {}),
        ]
        exits = [0] * self.count
        for axis in range(self.count):
            state = self.chain.axes[axis]
            if not delta[axis]:
                if not state.at_rest:
                    phases[0].sets[axis] = CubicAxis(axis=axis, speed=0, direction=state.direction)
                continue
            direction: Direction = 1 if delta[axis] > 0 else -1
            entry = round(p.v0 * share[axis])
            start, ahead = state.i, state.e
            if state.direction != direction or abs(state.i - entry) > SPEED_KEPT or state.d:
                phases[0].sets[axis] = CubicAxis(axis=axis, speed=entry, direction=direction)
                start, ahead = entry, state.e if state.direction == direction else -state.e
            exits[axis] = round(p.v1 * share[axis])
            # the ideal's distance to the target from where it is (not the move's nominal steps):
            # a residual carried from the moves before is not carried on
            remaining = (table.target[k][axis] - self.position[axis]) * direction * SIGMA - ahead
            ra, rd = self._aimed_jerks(p, axis, share[axis], (start, exits[axis]), remaining)
            phases[0].jerk[axis], phases[2].jerk[axis] = ra, -ra
            phases[4].jerk[axis], phases[6].jerk[axis] = -rd, rd
            if kd:  # the last ramp ends at exactly its exit speed (at rest: 0): set where it begins
                if exits[axis] + rd * kd < 0:
                    return None
                phases[4].sets[axis] = CubicAxis(
                    axis=axis, speed=exits[axis] + rd * kd, direction=direction
                )
                cruise = self._cruise_speed(p, axis, (start, exits[axis]), (ra, rd), remaining)
                if cruise is not None:
                    phases[3].sets[axis] = CubicAxis(axis=axis, speed=cruise, direction=direction)
        return phases, exits

    def _cruise_speed(
        self,
        p: Profile,
        axis: int,
        speeds: tuple[int, int],
        jerks: tuple[int, int],
        remaining: int,
    ) -> int | None:
        """The cruise speed, set where the cruise begins, that lands the axis after ramps of whole
        jerks `jerks`: the axes of a straight move then keep their proportion to the rounding of
        their ramps' travel, spread over the cruise, where landing by a ramp's jerk alone left the
        line by up to 109 steps mid-move (a few jerk units on the slower axis). None without a
        cruise, or where that speed is out of range or further from the first ramp's end than
        the landing's corrections may be."""
        if not p.nc:
            return None
        (start, exit_), (ra, rd) = speeds, jerks
        ka, kd = p.n1a * (p.n1a + p.n2a), p.n1d * (p.n1d + p.n2d)
        up = _ramp_travel([(p.n1a, ra), (p.n2a, 0), (p.n1a, -ra)], start)
        down = _ramp_travel([(p.n1d, -rd), (p.n2d, 0), (p.n1d, rd)], exit_ + rd * kd)
        cruise = round((remaining - up - down) / p.nc)
        limit = max(START_JUMP, ka + kd)
        if not 0 <= cruise <= min(self.speed_limit[axis], SIGMA):
            return None
        return cruise if abs(cruise - (start + ra * ka)) <= limit else None

    def _aimed_jerks(
        self, p: Profile, axis: int, share: float, speeds: tuple[int, int], remaining: int
    ) -> tuple[int, int]:
        """The ramps' whole jerks for one axis that bring it from its start speed to one cruise
        speed and from there to its exit speed, covering `remaining` (2^-31 step) as nearly as
        whole jerks can: the move's travel is affine in the cruise speed x, solved exactly."""
        start, exit_ = speeds
        ka, kd = p.n1a * (p.n1a + p.n2a), p.n1d * (p.n1d + p.n2d)
        # travel = start·(ta + nc) + ra·ua + exit·td + rd·ud
        ua, ud = _unit_travels(p)
        ta, td = 2 * p.n1a + p.n2a, 2 * p.n1d + p.n2d
        left = remaining - start * (ta + p.nc) - exit_ * td
        if ka and kd:
            x = (left + start * ua / ka + exit_ * ud / kd) / (ua / ka + ud / kd)
            ra, rd = round((x - start) / ka), round((x - exit_) / kd)
        elif ka:
            ra, rd = round(left / ua), 0
            x = start + ra * ka
        elif kd:
            x, ra = start, 0
            rd = round((x - exit_) / kd)
        else:
            return 0, 0
        if (
            max(abs(ra), abs(rd)) > self.jerk_limit[axis]
            or max(abs(ra) * p.n1a, abs(rd) * p.n1d) > self.accel_limit[axis]
            or x > self.speed_limit[axis]
        ):  # the planned speeds instead (the landing corrects what is left)
            ra = round((p.vc - p.v0) * share / ka) if ka else 0
            rd = round((p.vc - p.v1) * share / kd) if kd else 0
        return ra, rd

    def _built(
        self, phases: list[_Phase], target: tuple[int, ...]
    ) -> tuple[PhaseRun, dict[int, int]] | None:
        """The chain through the phases and each moving axis's miss; None when the firmware would
        refuse their segments."""
        run = run_phases(self.chain.axes, phases)
        if run is None:
            return None
        return run, self._misses(run, target)

    def _retune_starts(self, p: Profile, phases: list[_Phase], misses: dict[int, int]) -> bool:
        """An axis far off its target takes the nearest whole jerk on its first ramp instead: one
        unit more moves it by the unit ramp's travel and the speed it adds until the last ramp (set
        to its exit)."""
        ka = p.n1a * (p.n1a + p.n2a)
        until = p.nc  # the last ramp's start speed is set: the change ends there (or the move does)
        unit = _ramp_travel([(p.n1a, 1), (p.n2a, 0), (p.n1a, -1)]) + ka * until
        changed = False
        for axis, miss in misses.items():
            if abs(miss) <= LAND_SLACK // 2 or not unit:
                continue
            start = phases[0].sets.get(axis)
            from_rest = (start.speed if start is not None else self.chain.axes[axis].i) == 0
            # from rest a correction can only add speed: leave the axis short of its target, not
            # past it
            ra = phases[0].jerk.get(axis, 0) + (miss // unit if from_rest else round(miss / unit))
            speed = start.speed if start is not None else self.chain.axes[axis].i
            if (
                ra == phases[0].jerk.get(axis, 0)
                or abs(ra) > self.jerk_limit[axis]
                or abs(ra) * p.n1a > self.accel_limit[axis]
                or (speed or 0) + ra * ka > self.speed_limit[axis]
            ):
                continue
            phases[0].jerk[axis], phases[2].jerk[axis] = ra, -ra
            changed = True
        return changed

    def _resting_until_stop(self, phases: list[_Phase], axis: int) -> bool:
        start = phases[0].sets.get(axis)
        speed = start.speed if start is not None else self.chain.axes[axis].i
        return not speed and not phases[0].jerk.get(axis, 0)

    def _retune_stops(
        self, p: Profile, phases: list[_Phase], misses: dict[int, int], exits: list[int]
    ) -> bool:
        """An axis lands by its last ramp's jerk first: one unit more moves it by the travel of the
        unit ramp (its start speed set to keep the exit), so the nearest whole jerk is taken (within
        the limit)."""
        unit = _unit_ramp_travel(p.n1d, p.n2d)
        changed = False
        for axis, miss in misses.items():
            if axis not in phases[4].sets or abs(miss) <= LAND_SLACK // 4 or not unit:
                continue
            rd = -phases[4].jerk.get(axis, 0)
            # an axis still at rest until its last ramp can be corrected only by adding speed:
            # leave it short of its target, not past it
            extra = miss // unit if self._resting_until_stop(phases, axis) else round(miss / unit)
            if (
                not extra
                or abs(rd + extra) > self.jerk_limit[axis]
                or abs(rd + extra) * p.n1d > self.accel_limit[axis]
            ):
                continue
            rd += extra
            if rd < 0:
                continue
            set_ = phases[4].sets[axis]
            phases[4].sets[axis] = CubicAxis(
                axis=axis,
                speed=exits[axis] + rd * p.n1d * (p.n1d + p.n2d),
                direction=set_.direction,
            )
            phases[4].jerk[axis], phases[6].jerk[axis] = -rd, rd
            changed = True
        return changed

    def _land(
        self,
        p: Profile,
        phases: list[_Phase],
        run: PhaseRun,
        misses: dict[int, int],
        delta: tuple[int, ...],
    ) -> bool:
        """Speed sets that put each axis's ideal on its target, each at the earliest phase start
        where the change it needs, spread over the rest of the move, is within the limit (on the
        move's start an axis often has a set anyway: a corner); False when none is."""
        limit = max(START_JUMP, p.n1a * (p.n1a + p.n2a) + p.n1d * (p.n1d + p.n2d))
        begins = [sum(ph.n for ph in phases[:at]) for at in range(len(phases) + 1)]
        states = {at: run.states[at] for at in range(1, 7) if phases[at].n}
        corrected = False
        for axis, miss in misses.items():
            # an axis set at the move's start anyway lands exactly by that set, unless its cruise's
            # set lands it already
            exact = axis in phases[0].sets and axis not in phases[3].sets
            if abs(miss) <= (0 if exact else LAND_SLACK) or not delta[axis]:
                continue
            # its last ramp is set to end at its exit: the window ends before it
            pinned = axis in phases[4].sets
            for at in range(5):
                if at and (at not in states or (pinned and at == 4)):
                    continue
                ticks = (begins[4] if pinned else begins[-1]) - begins[at]
                if at == 0:
                    start = phases[0].sets.get(axis)
                    speed, accel = (
                        (start.speed if start is not None else self.chain.axes[axis].i),
                        0,
                    )
                else:
                    _, speed, accel, _ = states[at][axis]
                jump = round(miss / ticks) if ticks else limit + 1
                if abs(jump) <= limit and speed is not None and speed + jump >= 0:
                    phases[at].sets[axis] = CubicAxis(
                        axis=axis,
                        speed=speed + jump,
                        accel=accel,
                        direction=1 if delta[axis] > 0 else -1,
                    )
                    corrected = True
                    break
            else:
                if abs(miss) > LAND_SLACK and not self._bump(
                    phases, states, axis, miss, limit, delta[axis]
                ):
                    return False
                corrected = True
        self.corrections += corrected
        return True

    @staticmethod
    def _bump(
        phases: list[_Phase],
        states: dict[int, list[State]],
        axis: int,
        miss: int,
        limit: int,
        delta: int,
    ) -> bool:
        """A speed change over the longest phase without jerk where the axis moves fast enough to
        take it, set back exactly where it ends (two sets): for a move whose window before its
        last ramp is too short."""
        spans = [
            j
            for j in (1, 3, 5)
            if j in states
            and j + 1 in states
            and axis not in phases[j + 1].sets
            and abs(round(miss / phases[j].n)) <= limit
            and states[j][axis][1] + round(miss / phases[j].n) >= 0
            and states[j + 1][axis][1] >= 0
        ]
        if not spans:
            return False
        j = max(spans, key=lambda k: phases[k].n)
        jump = round(miss / phases[j].n)
        at, back = states[j][axis], states[j + 1][axis]
        direction: Direction = 1 if delta > 0 else -1
        phases[j].sets[axis] = CubicAxis(
            axis=axis, speed=at[1] + jump, accel=at[2], direction=direction
        )
        phases[j + 1].sets[axis] = CubicAxis(
            axis=axis, speed=back[1], accel=back[2], direction=direction
        )
        return True

    def _misses(self, run: PhaseRun, target: tuple[int, ...]) -> dict[int, int]:
        """Per moving axis, how far (2^-31 step, along its motion) its ideal would end short of
        `target`."""
        misses = {}
        for axis, state in enumerate(run.end):
            position = self.position[axis] + run.moved[axis]
            if target[axis] != self.position[axis] or not state.at_rest:
                misses[axis] = (target[axis] - position) * state.direction * SIGMA - state.e
        return misses

    def _emit(self, phases: list[_Phase], run: PhaseRun, line: int) -> None:
        """The move's segments out, the chain and the steppers past them."""
        for seg in _build(phases):
            self.out.add(seg, line, len(self.out))
        self.chain.axes = [AxisState(a.e, a.i, a.d, a.direction) for a in run.end]
        for axis, state in enumerate(self.chain.axes):
            self.position[axis] += run.moved[axis]
            self.peak[axis] = max(self.peak[axis], run.peak[axis])
            self.max_landing = max(self.max_landing, abs(state.e))

    # --- stops ------------------------------------------------------------------------------------

    def dwell(self, ticks: int, line: int) -> None:
        self.stop(line)
        self.speed = 0.0
        while ticks > 0:
            n = min(ticks, CUBIC_N_MAX)
            self.out.add(CubicSegment(n=n), line, len(self.out))
            ticks -= n

    def stop(self, line: int) -> None:
        """The machine must be at rest here (a dwell, a pause, the end)."""
        if not all(a.at_rest for a in self.chain.axes):
            raise JobError(f"{self.label} {line}: the plan does not come to rest here")


def _ramp_travel(phases: list[tuple[int, int]], i: int = 0) -> int:
    """How far (2^-31 step) phases of (ticks, jerk) travel from advance i and no acceleration
    (exact)."""
    d = travel = 0
    for n, r in phases:
        travel += n * i + n * (n - 1) // 2 * d + n * (n - 1) * (n - 2) // 6 * r
        i += n * d + n * (n - 1) // 2 * r
        d += n * r
    return travel


@lru_cache(maxsize=64)
def _unit_travels(p: Profile) -> tuple[int, int]:
    """How far unit jerks on the first ramp (with the cruise after it) and on the last move an
    axis (the same for every axis of the move)."""
    ua = _ramp_travel([(p.n1a, 1), (p.n2a, 0), (p.n1a, -1), (p.nc, 0)]) if p.n1a else 0
    ud = _unit_ramp_travel(p.n1d, p.n2d) if p.n1d else 0
    return ua, ud


def _unit_ramp_travel(n1: int, n2: int) -> int:
    """How far a ramp to rest of jerks −1, 0, +1 over n1, n2, n1 ticks travels from its start."""
    return _ramp_travel([(n1, -1), (n2, 0), (n1, 1)], n1 * (n1 + n2))


@lru_cache(maxsize=4096)
def _jerk_only(axis: int, jerk: int) -> CubicAxis:
    """An axis named only for its jerk (checked by run_phases; jerks repeat: a ramp's ±R)."""
    return CubicAxis(axis=axis, jerk=jerk)


def _build(phases: list[_Phase]) -> list[CubicSegment]:
    """The phases as segments: empty ones left out (their sets on the next), long ones split (a set
    on the first piece only). The segments are built without validation (n within its range, the
    axes in order, each axis a checked model)."""
    out = []
    pending: dict[int, CubicAxis] = {}  # sets of an empty phase go to the next one
    for ph in phases:
        left, sets = ph.n, {**pending, **ph.sets}
        pending = sets if left == 0 else {}
        while left > 0:
            n = min(left, CUBIC_N_MAX)
            axes = []
            for axis in sorted(set(sets) | {a for a, r in ph.jerk.items() if r}):
                r = ph.jerk.get(axis, 0)
                s = sets.get(axis)
                if s is None:
                    axes.append(_jerk_only(axis, r))
                elif (s.jerk or 0) == r:
                    axes.append(s)
                else:
                    axes.append(
                        CubicAxis(
                            axis=axis,
                            speed=s.speed,
                            accel=s.accel,
                            direction=s.direction,
                            jerk=r if r else None,
                        )
                    )
            out.append(CubicSegment.model_construct(n=n, axes=tuple(axes)))
            left -= n
            sets = {}
    return out


__all__ = ["ScurvePlanner"]
