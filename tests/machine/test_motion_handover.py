"""A motion cut short hands the stream over to the motion that follows it (a feed override, lines
added to an open job), which goes on with the same stream. When the board runs dry as they hand
over, the frames the cut motion sent last are refused and never run: the follower ends as the
stream did, with the board starved (the job then goes on from rest), instead of counting on them."""

from __future__ import annotations

import time

from quadstep.kernel.motion import AxisMove
from quadstep.link import Link
from quadstep.machine.motion import STARVED, Motion
from quadstep.planner.segments import SegmentArrays
from quadstep.protocol import Segment, State

TICK_HZ = 10_000
DECELS = (200, 200, 200)
CRUISE = Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=2048, vn=2048, r=0),))


def wait_state(link: Link, state: State) -> None:
    deadline = time.monotonic() + 10
    while link.status().state != state:
        assert time.monotonic() < deadline, f"the board never was {state.name}"


def test_a_follower_ends_starved_when_the_board_ran_dry_as_they_handed_over(start_emulator) -> None:
    emu = start_emulator(tick_hz=TICK_HZ, axes=3, queue=4)
    segments = SegmentArrays.of([CRUISE] * 8, 3)
    with Link.open(emu.url) as link:
        link.send(CRUISE)  # it ends moving with nothing behind it: the board stops it (an underrun)
        wait_state(link, State.HOLDING)
        cut = Motion(link, segments, DECELS)
        # cut before it streams: its four segments reach a board that is stopping, refused (BUSY)
        assert cut.cut(4)
        ended = cut.start().wait(10)
        assert ended is not None and ended.ended_by == "cut"
        wait_state(link, State.STARVED)  # the link learns the stream ran dry
        follower = Motion(link, segments, DECELS, first=4, follows=cut).start()
        end = follower.wait(10)
        status = link.status()
    assert end is not None and end.ended_by == STARVED, end
    assert status.state == State.IDLE and status.segments_done == 1  # none of the eight ran
