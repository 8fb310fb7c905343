"""The decelerations of a stop along the path (machine/along_path.py): in proportion to the speeds
of a straight run of segments, never above an axis's own, and the run they are given for."""

from __future__ import annotations

from fractions import Fraction

from hypothesis import given
from hypothesis import strategies as st

from quadstep.kernel.motion import AxisMove
from quadstep.machine.along_path import along_path, path_decels, same_direction
from quadstep.planner.segments import SegmentArrays
from quadstep.protocol import CubicSegment, Segment

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


def test_one_direction_within_the_speeds_rounding() -> None:
    assert same_direction((3000, 1000, 0), (6000, 2001, 0))
    assert same_direction((3000, 1000, 0), (30, 10, 0))
    assert not same_direction((3000, 1000, 0), (6000, 2100, 0))
    assert not same_direction((3000, 1000, 0), (3000, -1000, 0))
    assert not same_direction((3000, 1000, 0), (3000, 1000, 5))


def test_the_run_from_the_running_segment_to_a_corner() -> None:
    line = [seg(300, (0, 1, 0, 3000), (1, 1, 0, 1000)), seg(900, (0, 1, 3000, 3000), (1, 1, 1000, 1000)),
            seg(300, (0, 1, 3000, 900), (1, 1, 1000, 300))]
    corner = seg(300, (0, 1, 900, 900), (1, -1, 300, 300))
    arrays = SegmentArrays.of([*line, corner], 3)
    along = along_path(arrays, 1, 4, 70000, (3277, 3277, 3277))
    assert along is not None
    # segments 1 and 2 (done counts 70000 and 70001, mod 2^16), decelerations from the fastest
    assert (along.first, along.last) == (70000 % 65536, 70001 % 65536)
    assert along.decels == (3277, 1092, 3277)
    # only what was sent
    sent_one = along_path(arrays, 1, 2, 5, (3277, 3277, 3277))
    assert sent_one is not None and (sent_one.first, sent_one.last) == (5, 5)
    assert along_path(arrays, 4, 4, 5, (3277, 3277, 3277)) is None  # nothing running of it


class Cubic:
    def segment(self, i: int) -> Segment | CubicSegment:
        return CubicSegment(n=10, axes=())


def test_no_path_for_a_jerk_limited_segment_or_one_that_moves_nothing() -> None:
    assert along_path(Cubic(), 0, 1, 0, DECELS) is None
    assert along_path(SegmentArrays.of([seg(10)], 3), 0, 1, 0, DECELS) is None
