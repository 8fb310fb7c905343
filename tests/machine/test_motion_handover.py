"""A motion cut short (a feed override, lines added to an open job) goes on in place with the plan
made again from the cut (go_on()), without a stop and whether or not it has reached the cut yet;
where that plan let go of what ran, its numbering is shifted. Where the board runs dry while the
motion waits at the cut, the motion ends as the stream did, with the board starved (the job then
goes on from rest), and takes no plan after that."""

from __future__ import annotations

import time

from quadstep.kernel.motion import AxisMove
from quadstep.link import Link
from quadstep.machine.motion import STARVED, Motion
from quadstep.planner.segments import SegmentArrays
from quadstep.protocol import Segment, State

TICK_HZ = 10_000
DECELS = (200, 200, 200)
# 0.1 s each: four slots hold 0.4 s, which a host on a busy computer keeps filled
CRUISE = Segment(n=1000, axes=(AxisMove(axis=0, direction=1, v0=2048, vn=2048, r=0),))
STOP = Segment(n=1000, axes=(AxisMove(axis=0, direction=1, v0=2048, vn=0, r=0),))


def plan(cruises: int) -> SegmentArrays:
    """`cruises` segments at one speed, then a stop."""
    return SegmentArrays.of([CRUISE] * cruises + [STOP], 3)


def travel(link: Link, segments: SegmentArrays) -> int:
    """The X travel of `segments` streamed whole from rest, as a reference."""
    start = link.status().position[0]
    end = Motion(link, segments, DECELS).start().wait(10)
    assert end is not None and end.ended_by == "done", end
    return end.position[0] - start


def wait_state(link: Link, state: State) -> None:
    deadline = time.monotonic() + 10
    while link.status().state != state:
        assert time.monotonic() < deadline, f"the board never was {state.name}"


def test_a_motion_cut_goes_on_in_place_with_the_plan_made_again(start_emulator) -> None:
    emu = start_emulator(tick_hz=TICK_HZ, axes=3, queue=4)
    with Link.open(emu.url) as link:
        before = link.status()
        motion = Motion(link, plan(7), DECELS)
        assert motion.cut(4)
        motion.start()
        while motion.sent < 4:  # at the cut, waiting there (the board has 0.4 s of motion)
            time.sleep(0.001)
        # the plan made again: the same four before the cut, then five more and the stop
        assert motion.go_on(plan(9), 0, 10, ())
        end = motion.wait(10)
        status = link.status()
        reference = travel(link, plan(9))
    assert end is not None and end.ended_by == "done", end
    assert end.segments_done == 10 and status.segments_done - before.segments_done == 10
    assert end.position[0] - before.position[0] == reference
    assert link.stats.starvations == 0


def test_a_plan_that_let_go_of_what_ran_goes_on_renumbered(start_emulator) -> None:
    emu = start_emulator(tick_hz=TICK_HZ, axes=3, queue=4)
    with Link.open(emu.url) as link:
        start = link.status().position[0]
        motion = Motion(link, plan(7), DECELS)
        assert motion.cut(6)
        motion.start()
        while motion.sent < 2:  # the board has the first two at least
            time.sleep(0.001)
        # the new plan begins at the old one's segment 2: its 4 is the old 6; ten more to its end
        assert motion.go_on(plan(8), 2, 9, ())
        assert motion.first == -2
        end = motion.wait(10)
        reference = travel(link, plan(10))
    assert end is not None and end.ended_by == "done", end
    assert end.segments_done == 11 and end.position[0] - start == reference


def test_a_motion_at_its_cut_ends_starved_when_the_board_runs_dry(start_emulator) -> None:
    emu = start_emulator(tick_hz=TICK_HZ, axes=3, queue=4)
    segments = SegmentArrays.of([CRUISE] * 8, 3)
    with Link.open(emu.url) as link:
        link.send(CRUISE)  # it ends moving with nothing behind it: the board stops it (an underrun)
        wait_state(link, State.HOLDING)
        motion = Motion(link, segments, DECELS)
        # cut before it streams: its four segments reach a board that is stopping, refused (BUSY)
        assert motion.cut(4)
        end = motion.start().wait(10)
        status = link.status()
        taken = motion.go_on(segments, 0, 8, ())
    assert end is not None and end.ended_by == STARVED, end
    assert not taken  # ended: the job goes on from rest
    assert status.state == State.IDLE and status.segments_done == 1  # none of the eight ran
