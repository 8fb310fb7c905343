"""The decelerations of a stop along the path (machine/along_path.py): in proportion to the speeds
of a straight run of segments, never above an axis's own, and the run they are given for."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from quadstep.kernel.motion import AxisMove, CubicAxis
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.machine.along_path import (
    QUADRATIC_UNIT,
    ROUNDING,
    PathSpeeds,
    Speeds,
    along_path,
    path_decels,
    same_direction,
)
from quadstep.planner.segments import SegmentArrays
from quadstep.planner.stream import Stream
from quadstep.protocol import CubicSegment, Segment
from quadstep.protocol.cubic_run import SpeedChain

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
DECELS = (3277, 3277, 1638)


def seg(n: int, *moves: tuple[int, int, int, int]) -> Segment:
    """A segment of (axis, direction, v0, vn) moves, residuals 0."""
    return Segment(
        n=n, axes=tuple(AxisMove(axis=a, direction=d, v0=v0, vn=vn, r=0) for a, d, v0, vn in moves)
    )


def test_the_axis_slowest_to_stop_keeps_its_own_and_the_others_follow_its_proportion() -> None:
    assert path_decels((3000, 1000, 0), DECELS) == (3277, 1092, 1638)  # Z still: its own
    assert path_decels((-3000, 1000, 500), DECELS) == (3277, 1092, 546)
    # Z's own deceleration is half the others': at half their speed it is the one to wait for
    assert path_decels((1000, 600, 800), DECELS) == (2047, 1228, 1638)
    assert path_decels((9, 1, 0), DECELS) == (3277, 364, 1638)
    assert path_decels((60000, 1, 0), DECELS) == (3277, 1, 1638)  # at least 1


@given(
    st.lists(st.integers(-65535, 65535), min_size=3, max_size=3),
    st.lists(st.integers(1, 8191), min_size=3, max_size=3),
)
def test_no_axis_decelerates_faster_than_its_own_and_all_stop_together(
    speeds: list[int], decels: list[int]
) -> None:
    out = path_decels(speeds, decels)
    assert all(1 <= o <= d for o, d in zip(out, decels))
    moving = [axis for axis in range(3) if speeds[axis]]
    if moving:
        # stopping times |v| / a: the longest is every moving axis's, to the rounding of a (an axis
        # too slow for one unit of deceleration gets 1 and stops sooner)
        longest = max(Fraction(abs(speeds[a]), decels[a]) for a in moving)
        for axis in moving:
            v = abs(speeds[axis])
            assert Fraction(v, out[axis] + 1) < longest
            assert longest <= Fraction(v, out[axis]) or (out[axis] == 1 and longest > v)


def quadratic(*values: int) -> Speeds:
    """Speeds as a quadratic segment's (1/4096 step per tick) give them."""
    return Speeds(tuple(v << QUADRATIC_UNIT for v in values), ROUNDING << QUADRATIC_UNIT)


def test_one_direction_within_the_speeds_rounding() -> None:
    assert same_direction(quadratic(3000, 1000, 0), quadratic(6000, 2001, 0))
    assert same_direction(quadratic(3000, 1000, 0), quadratic(30, 10, 0))
    assert not same_direction(quadratic(3000, 1000, 0), quadratic(6000, 2100, 0))
    assert not same_direction(quadratic(3000, 1000, 0), quadratic(3000, -1000, 0))
    assert not same_direction(quadratic(3000, 1000, 0), quadratic(3000, 1000, 5))


def test_the_run_from_the_running_segment_to_a_corner() -> None:
    line = [seg(300, (0, 1, 0, 3000), (1, 1, 0, 1000)), seg(900, (0, 1, 3000, 3000), (1, 1, 1000, 1000)),
            seg(300, (0, 1, 3000, 900), (1, 1, 1000, 300))]
    corner = seg(300, (0, 1, 900, 900), (1, -1, 300, 300))
    arrays = SegmentArrays.of([*line, corner], 3)
    speeds = PathSpeeds(3).reader(arrays, 0)  # quadratic segments are read, whatever was kept
    along = along_path(speeds, 1, 4, 70000, (3277, 3277, 3277))
    assert along is not None
    # segments 1 and 2 (done counts 70000 and 70001, mod 2^16), decelerations from the fastest
    assert (along.first, along.last) == (70000 % 65536, 70001 % 65536)
    assert along.decels == (3277, 1092, 3277)
    # only what was sent
    sent_one = along_path(speeds, 1, 2, 5, (3277, 3277, 3277))
    assert sent_one is not None and (sent_one.first, sent_one.last) == (5, 5)
    assert along_path(speeds, 4, 4, 5, (3277, 3277, 3277)) is None  # nothing running of it
    assert along_path(PathSpeeds(3).reader(SegmentArrays.of([seg(10)], 3), 0), 0, 1, 0, DECELS) is None


SCURVE = CONFIG.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)}
)


def diagonal(tmp_path: Path) -> Stream:
    """An S-curve plan of a 3:1 diagonal there and back: per leg, from rest, three phases up to
    the feed, a cruise, three down to rest."""
    path = tmp_path / "diagonal.gcode"
    path.write_text("G21 G90 F2400\nG1 X30 Y10\nG1 X0 Y0\n")
    stream = load_job(path, SCURVE, (0, 0, 0)).plan.segments
    assert isinstance(stream, Stream)
    assert [type(s) for s in stream.segments(1)] == [CubicSegment] * 14
    return stream


def test_a_jerk_limited_run_takes_its_speeds_from_the_firmware_chain(tmp_path: Path) -> None:
    stream = diagonal(tmp_path)
    segments = list(stream)
    path = PathSpeeds(3)
    # sent a frame at a time, from the plan's anchor at rest on; the board has run none yet
    path.sent(0, segments[:1], 0)
    path.sent(1, segments[1:4], 0)
    path.sent(4, segments[4:15], 0)
    speeds = path.reader(stream, 0)
    cruise = speeds(4)
    assert cruise is not None
    chain = SpeedChain.at_rest(3)
    for segment in segments[:5]:
        chain.follow(segment)
    assert cruise.values == (chain.i[0], chain.i[1], 0)  # at the feed, 3:1
    assert abs(Fraction(cruise.values[0], cruise.values[1]) - 3) < Fraction(1, 1000)
    leg = [speeds(k) for k in range(1, 8)]
    fastest = max((v for v in leg if v is not None), key=lambda v: v.values[0])
    # each leg is one straight run, up from rest and down to it; the decelerations from its fastest
    for running in range(1, 8):
        along = along_path(speeds, running, 15, 100 + running, DECELS)
        assert along is not None and (along.first, along.last) == (100 + running, 107)
        assert along.decels == path_decels(fastest.values, DECELS)
    back = along_path(speeds, 9, 15, 109, DECELS)  # the way back: a run of its own
    assert back is not None and (back.first, back.last) == (109, 114)
    # nothing moves in the anchor; what was not sent is not known
    assert along_path(speeds, 0, 15, 100, DECELS) is None
    assert along_path(PathSpeeds(3).reader(stream, 0), 4, 15, 104, DECELS) is None


def cruise(x: int, y: int) -> CubicSegment:
    """100 ticks at speeds set to `x` and `y` (2^-31 step per tick)."""
    return CubicSegment(n=100, axes=(CubicAxis(axis=0, speed=x), CubicAxis(axis=1, speed=y)))


def test_cubic_speeds_are_one_direction_within_a_share_of_the_fastest_axis() -> None:
    """Y's speed 1 % of X's from 3:1 is one direction (about the spread of an S-curve's jerks), 5 %
    is another."""
    items = [cruise(3_000_000, 1_000_000), cruise(3_000_000, 1_030_000), cruise(3_000_000, 1_150_000)]
    path = PathSpeeds(3)
    path.sent(0, items, 0)
    speeds = path.reader(Listed(items), 0)
    along = along_path(speeds, 0, 3, 0, DECELS)
    assert along is not None and (along.first, along.last) == (0, 1)
    assert along.decels == path_decels((3_000_000, 1_000_000, 0), DECELS)


class Listed:
    def __init__(self, items: list[CubicSegment]) -> None:
        self.items = items

    def segment(self, i: int) -> Segment | CubicSegment:
        return self.items[i]


def test_what_has_run_is_let_go_of(tmp_path: Path) -> None:
    stream = diagonal(tmp_path)
    segments = list(stream)
    path = PathSpeeds(3)
    path.sent(0, segments[:8], 0)
    path.sent(8, segments[8:15], 6)  # six have run
    speeds = path.reader(stream, 0)
    assert speeds(5) is None and speeds(6) is not None and speeds(9) is not None
