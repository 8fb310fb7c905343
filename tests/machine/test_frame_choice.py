"""The frame kinds a motion sends: the ones the board takes the most segments a second in."""

from __future__ import annotations

from quadstep.protocol.frame_choice import frame_choice
from quadstep.protocol import Board, Capability, IdentifyReply, Segment
from quadstep.protocol.frames import next_frame
from quadstep.kernel.motion import AxisMove
from quadstep.protocol.segment_run import RunChain, Segments

EVERY_FRAME = Capability.QUADRATIC_SEGMENTS | Capability.SEGMENTS | Capability.CUBIC_RUNS


def identity(board: Board, capabilities: int = EVERY_FRAME) -> IdentifyReply:
    return IdentifyReply(
        protocol_version=3,
        fw_major=1,
        fw_minor=0,
        fw_patch=0,
        board=board,
        axis_count=3,
        queue_capacity=14,
        speed_shift=12,
        n_max=1022,
        tick_hz=32_000,
        capabilities=capabilities,
        next_seq=0,
        boot_id=1,
    )


class _Run:
    def __init__(self, segments: list[Segment]) -> None:
        self.segments = segments

    def segment(self, i: int) -> Segment:
        return self.segments[i]


def test_an_avr_board_takes_quadratic_segments_one_a_frame_and_cubic_ones_in_runs() -> None:
    for board in (Board.ATMEGA328P, Board.ATMEGA2560):
        choice = frame_choice(identity(board))
        assert (choice.quadratic_runs, choice.cubic_runs) == (False, True)
    choice = frame_choice(identity(Board.EMULATOR))
    assert (choice.quadratic_runs, choice.cubic_runs) == (True, True)


def test_never_a_frame_kind_the_firmware_lacks() -> None:
    choice = frame_choice(identity(Board.EMULATOR, Capability.QUADRATIC_SEGMENTS))
    assert (choice.quadratic_runs, choice.cubic_runs) == (False, False)


def test_without_quadratic_runs_each_segment_goes_alone() -> None:
    run = [
        Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=2000 + i, vn=2001 + i, r=0),))
        for i in range(5)
    ]
    chain = RunChain(3)
    chain.follow(run[0])
    assert isinstance(next_frame(_Run(run), 1, 5, chain.copy(), 7), Segments)
    alone = next_frame(_Run(run), 1, 5, chain, 7, quadratic_runs=False)
    assert alone == run[1]
