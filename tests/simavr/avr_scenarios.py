"""Segment streams for the board tests, built the way the host builds them:
each axis carries its residual from segment to segment (engine_model), so
the streams are what a planner sends and the firmware must follow exactly.

A stream is a list of runs; each run starts and ends at rest, so between runs
the board goes IDLE and the next run starts a new one (motion ticks go on).
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

from quadstep.kernel.engine_model import advance, residual
from quadstep.kernel.cubic_chain import CubicChain
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.motion import CubicAxis
from quadstep.protocol import Segment
from quadstep.kernel.motion import AxisMove
from quadstep.kernel.fixed import D, N_MAX

# Per axis: (direction, v0, vn); an axis left out does not move.
Moves = dict[int, tuple[int, int, int]]


@dataclass
class ChainBuilder:
    """Turns (n, moves) into Segments with exact residuals, axis by axis."""

    axis_count: int
    ideal2: list[int] = field(default_factory=list)
    position: list[int] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.ideal2 = [0] * self.axis_count
        self.position = [0] * self.axis_count

    def segment(self, n: int, moves: Moves) -> Segment:
        axes = []
        for axis in sorted(moves):
            direction, v0, vn = moves[axis]
            r = residual(self.ideal2[axis], self.position[axis], direction)
            if r == D and v0 == D and vn == D:
                vn = D - 1  # the one input PROTOCOL.md excludes
            mv = AxisMove(axis=axis, direction=direction, v0=v0, vn=vn, r=r)
            self.ideal2[axis], self.position[axis] = advance(self.ideal2[axis], self.position[axis], n, mv)
            axes.append(mv)
        return Segment(n=n, axes=tuple(axes))


def dwell(n: int = N_MAX) -> Segment:
    """A segment that moves nothing: gives the host a head start filling the queue."""
    return Segment(n=n, axes=())


def full_speed(axis_count: int, n: int = 1000, count: int = 4) -> list[list[Segment]]:
    """Every axis stepping every tick (v = D), then a stop; axis 1 runs negative."""
    b = ChainBuilder(axis_count)
    dirs = {a: -1 if a == 1 else 1 for a in range(axis_count)}
    run = [dwell()]
    run += [b.segment(n, {a: (dirs[a], D, D) for a in range(axis_count)}) for _ in range(count)]
    run.append(b.segment(n, {a: (dirs[a], D, 0) for a in range(axis_count)}))
    return [run]


def ramps_and_reversals(axis_count: int) -> list[list[Segment]]:
    """Accelerate, cruise, decelerate; reverse directions between and within runs."""
    b = ChainBuilder(axis_count)
    runs = []
    for sign in (1, -1):
        run = [dwell(400)]
        profile = [(300, 0, 1500), (500, 1500, 4000), (700, 4000, 4000), (500, 4000, 1200), (300, 1200, 0)]
        for n, v0, vn in profile:
            moves = {a: (sign * (-1 if a % 2 else 1), v0 // (a + 1), vn // (a + 1)) for a in range(axis_count)}
            run.append(b.segment(n, moves))
        # Axis 0 turns round inside the run (through rest), the others wait.
        run.append(b.segment(250, {0: (-sign, 0, 3000)}))
        run.append(b.segment(250, {0: (-sign, 3000, 0)}))
        runs.append(run)
    return runs


def random_runs(axis_count: int, seed: int, runs: int = 3, per_run: int = 12) -> list[list[Segment]]:
    """Random lengths (one-tick segments included), speeds, directions and idle axes."""
    rng = random.Random(seed)
    b = ChainBuilder(axis_count)
    out = []
    for _ in range(runs):
        run = [dwell()]
        speed = [0] * axis_count
        direction = [1] * axis_count
        for i in range(per_run):
            n = rng.choice([1, 2, 3, rng.randint(150, 400), rng.randint(400, N_MAX), N_MAX])
            last = i == per_run - 1
            moves: Moves = {}
            for a in range(axis_count):
                if speed[a] == 0 and rng.random() < 0.3:
                    direction[a] = -direction[a]  # turn round only from rest
                v0 = speed[a]
                vn = 0 if last else rng.choice([0, rng.randint(1, D), D])
                if v0 == 0 and vn == 0 and rng.random() < 0.5:
                    continue  # this axis sits the segment out
                moves[a] = (direction[a], v0, vn)
                speed[a] = vn
            run.append(b.segment(n, moves))
        out.append(run)
    return out


def s_curve(axis_count: int, n1: int, n2: int, cruise: int, jerks: dict[int, int]) -> list[CubicSegment]:
    """A rest-to-rest jerk-limited move: per axis jerk +r for n1 ticks, none for n2, -r for n1, a cruise,
    then the same with the jerks negated, which brings every axis back to rest exactly."""
    def phase(n: int, sign: int) -> CubicSegment:
        return CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=sign * r) for a, r in sorted(jerks.items()) if r))

    accel = [phase(n1, 1), CubicSegment(n=n2), phase(n1, -1)]
    decel = [phase(n1, -1), CubicSegment(n=n2), phase(n1, 1)]
    return accel + [CubicSegment(n=cruise)] + decel


def jerk_phases(n: int, count: int, axes: int = 3) -> list[CubicSegment]:
    """Every axis near 0.9 step per tick, its jerk +r, -r, -r, +r in turn (the acceleration rises and
    falls back, the speed swings a little): every axis steps nearly every tick, in jerk phases, the
    costliest cubic tick."""
    sigma = 1 << 31
    r = min(32767, max(1, int(0.02 * sigma / (n * n))))  # the jerk field's limit for the shortest segments
    start = CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, speed=int(0.9 * sigma), jerk=r) for a in range(axes)))
    pattern = (-r, -r, r, r)
    segs = [start]
    for k in range(count - 2):
        segs.append(CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=pattern[k % 4]) for a in range(axes))))
    segs.append(CubicSegment(n=1, axes=tuple(CubicAxis(axis=a, speed=0) for a in range(axes))))
    return segs


def cubic_runs(axis_count: int, seed: int, runs: int = 2, shortest: int = 150) -> list[list[Segment | CubicSegment]]:
    """Runs of cubic segments the way a jerk-limited plan has them: S-curves on every axis with
    random jerks, turned round at rest by state sets, with corners (a set mid-motion) and a long cruise,
    each checked against the firmware's own rules (CubicChain) as it is made."""
    rng = random.Random(seed)
    out: list[list[Segment | CubicSegment]] = []
    chain = CubicChain(axis_count)
    for _ in range(runs):
        run: list[Segment | CubicSegment] = []
        for _ in range(3):
            # phases of a few hundred ticks: the board's main loop prepares a cubic segment in about
            # 19,000 cycles (docs/CUBIC.md), so shorter ones in a row would outrun it
            n1, n2 = rng.randint(shortest, shortest + 250), rng.randint(shortest, shortest + 150)
            fastest = int(0.4 * 2**31 / (n1 * (n1 + n2)))  # a jerk that peaks at 0.4 step per tick
            jerks = {a: rng.randint(0, fastest) for a in range(axis_count)}
            turn = tuple(CubicAxis(axis=a, speed=0, direction=rng.choice((1, -1))) for a in range(axis_count))
            run.append(CubicSegment(n=rng.randint(shortest, shortest + 50), axes=turn))
            run += s_curve(axis_count, n1, n2, rng.choice((shortest, 500, 30000)), jerks)
        # a corner: every axis set to a new speed mid-motion, then slowed to rest by a jerk
        corner = tuple(CubicAxis(axis=a, speed=rng.randint(1, 2**30), direction=rng.choice((1, -1)))
                       for a in range(axis_count))
        run.append(CubicSegment(n=300, axes=corner))
        run.append(CubicSegment(n=shortest, axes=tuple(CubicAxis(axis=a, speed=0) for a in range(axis_count))))
        for seg in run:
            chain.advance(seg)  # every segment valid where it stands
        out.append(run)
    return out


def quadratic_into_cubic(axis_count: int) -> list[list[Segment | CubicSegment]]:
    """Quadratic segments that end moving, carried on by cubic ones with no state set (the chain takes the
    quadratic's exact end: its residual and end speed), slowed to rest by a jerk-limited ramp."""
    b = ChainBuilder(axis_count)
    run: list[Segment | CubicSegment] = [dwell(300)]
    dirs = {a: -1 if a == 1 else 1 for a in range(axis_count)}
    run.append(b.segment(400, {a: (dirs[a], 0, 1500 + 500 * a) for a in range(axis_count)}))
    run.append(b.segment(301, {a: (dirs[a], 1500 + 500 * a, 2000 + 500 * a) for a in range(axis_count)}))
    # from speed v (v/4096 step per tick) to rest: jerk -r over n, then +r over n (the acceleration back to 0)
    n = 700
    jerks = {a: -((2000 + 500 * a) * 2**19 // (n * n)) for a in range(axis_count)}  # ends just above rest
    run.append(CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=r) for a, r in jerks.items())))
    run.append(CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=-r) for a, r in jerks.items())))
    run.append(CubicSegment(n=50, axes=tuple(CubicAxis(axis=a, speed=0) for a in range(axis_count))))
    return [run]


def every_message_kind(axis_count: int, cubic: bool = True, pace: int = 0) -> bytes:
    """Wire bytes (no flow control) that exercise every path of the
    firmware while axes move: SEGMENT (the Uno takes no SEGMENTS), SET_POSITION (accepted at rest,
    refused while moving), STATUS, IDENTIFY, and damaged frames of each
    framing error, and (with `cubic`) a ramp move as CUBIC_SEGMENT and CUBIC_SEGMENTS. For the stack's
    high-water mark. Each round's replies take the line back nearly as long as its frames take it out;
    `pace` empty frames after each round give the board the time a host's flow control would (without
    them a round can find the receive ring full: a frame is lost, the motion runs dry, and whether the
    final STOP comes first is a matter of a few cycles)."""
    from quadstep.protocol import Identify, SetPosition, Status, Stop, encode
    from quadstep.protocol.framing import encode_frame

    from quadstep.protocol.cubic_run import SpeedChain
    from quadstep.protocol.cubic_run import pack as cubic_pack

    b = ChainBuilder(axis_count)
    out = [b"\x00", encode(Identify(), 1), encode(SetPosition(positions={a: 5 * a for a in range(axis_count)}), 0)]
    b.position = [5 * a for a in range(axis_count)]
    b.ideal2 = [2 * D * p for p in b.position]
    # a ramp move of cubic segments from rest (long enough that the frames after it arrive while it runs): a
    # CUBIC_SEGMENT, then a CUBIC_SEGMENTS frame that sets axis 0 to the state it has
    jerk, n = 10, 2000
    speeds = SpeedChain.at_rest(axis_count)
    first = CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=jerk) for a in range(axis_count)))
    speeds.follow(first)
    ramp = [CubicSegment(n=n, axes=(CubicAxis(axis=0, speed=speeds.i[0], accel=speeds.d[0], jerk=-jerk),)
                         + tuple(CubicAxis(axis=a, jerk=-jerk) for a in range(1, axis_count))),
            CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=-jerk) for a in range(axis_count))),
            CubicSegment(n=n, axes=tuple(CubicAxis(axis=a, jerk=jerk) for a in range(axis_count)))]
    seq = 1
    if cubic:
        out += [encode(first, 1), encode(cubic_pack(ramp, speeds), 2)]  # type: ignore[arg-type]
        seq = 3
    for i in range(8):
        last = i == 7
        segments = [b.segment(200, {a: (1, D // 2, D // 2) for a in range(axis_count)}),
                    b.segment(200, {a: (1, D // 2, 0 if last else D // 2) for a in range(axis_count)})]
        for segment in segments:
            out.append(encode(segment, seq))
            seq += 1
        out += [encode(Status(), 9), encode(Identify(), 9), encode_frame(b"\x10\x05\x01"), b"\x07" * 70 + b"\x00",
                b"\x05\x01\x02\x03\x04\x05\x06\x00"]
        out.append(encode(SetPosition(positions={0: 1}), seq))  # refused: BUSY
        out.append(b"\x00" * pace)
        seq += 1
    out.append(encode(Stop(), 50))
    return b"".join(out)


def hold_from_full_speed(axis_count: int, pad: int = 0, segments: int = 15) -> bytes:
    """Wire bytes (no flow control needed): `segments` segments of 300 ticks with every axis near full speed
    (the costliest hold to begin, and to run), then after `pad` empty frames (20 µs each on the line) a HOLD
    at 800 / 2^24 step per tick² (about 20,000 ticks to rest): a HOLD_ALONG naming every segment, as a
    motion's halt sends (its path's decelerations the same, all axes moving alike)."""
    from quadstep.protocol import HoldAlong, encode

    seg = Segment(n=300, axes=tuple(AxisMove(axis=a, direction=1, v0=D - 1, vn=D - 1, r=0) for a in range(axis_count)))
    job = b"\x00" + b"".join(encode(seg, i) for i in range(segments))
    decel = (800,) * axis_count + (0,) * (4 - axis_count)
    hold = HoldAlong(decel=decel, path_decel=decel, first=0, last=segments - 1)  # type: ignore[arg-type]
    return job + b"\x00" * pad + encode(hold, segments)


def hold_answered(replies: bytes, axis_count: int) -> bool:
    """Whether the board answered a HOLD (its status, HOLDING). Bytes that find the receive ring full are
    dropped: where a line kept busy outruns the main loop (50 kHz with every axis stepping), a HOLD's last
    bytes can be among them, the board never takes it, and its queue runs dry instead (an underrun)."""
    from quadstep.protocol import Decoder, State, StatusReport

    items = Decoder("to_host", axis_count=axis_count).feed(replies)
    return any(isinstance(r, StatusReport) and r.state == State.HOLDING
               for r in (getattr(item, "message", None) for item in items))


def status_during_a_hold(axis_count: int) -> bytes:
    """hold_from_full_speed and STATUS requests all through the deceleration, each of which works the hold's
    steps out (the deepest stack the firmware reaches)."""
    from quadstep.protocol import Status, encode

    return hold_from_full_speed(axis_count) + b"".join(encode(Status(), 16) + b"\x00" * 400 for _ in range(40))


def takeups(axis_count: int) -> list[list[Segment | CubicSegment]]:
    """Streams with backlash take-ups as the compensation stage makes them (docs/BACKLASH.md), 0.1 mm on X
    and Y: a small pocket (take-ups in the stepovers' pauses; an axis stopping between quadratic segments
    before a cubic window) and a circle (take-ups in and around its quadrants, cubic windows among quadratic
    segments), each a run that starts with every carriage pushed +."""
    from backlash_helpers import backlash_config, circle_gcode, pocket_gcode, pushed_plus
    from quadstep.backlash.base import from_arrays
    from quadstep.backlash.compensate import compensate
    from quadstep.gcode import parse_gcode
    from quadstep.planner.plan import plan_program

    config = backlash_config((0.1, 0.1) + (0.0,) * (axis_count - 2))
    start = (0,) * axis_count
    out: list[list[Segment | CubicSegment]] = []
    for gcode in (pocket_gcode(2, 0.5, 0.25, 10), circle_gcode(1, 10)):
        plan = plan_program(parse_gcode(gcode, config.axis_names, start, config.arc_tolerance), config, start)
        compensated = compensate(from_arrays(plan.segments), config, pushed_plus(config))
        assert {t.axis for t in compensated.takeups} == {0, 1}
        out.append([dwell(300), *compensated.stream.segments()])
    return out
