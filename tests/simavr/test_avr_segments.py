"""SEGMENTS and CUBIC_SEGMENTS on the board: the same streams sent as chained records, several to a frame
(PROTOCOL.md §5.2), make exactly the steps of the emulator and of the host's prediction on the real AVR firmware
in simavr, and take far fewer bytes than one segment a frame. The Uno takes CUBIC_SEGMENTS but no SEGMENTS: the
host sends an AVR board one SEGMENT a frame, which it takes faster (protocol/frame_choice.py), and the Uno's
build leaves the reader out."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import avr_scenarios
from avr_sim import Outputs, run_input
from quadstep.kernel.engine_model import predict
from quadstep.link import Link
from quadstep.protocol import AckReason, Capability, Decoder, ErrorCode, Identify, Segment, StatusReport, encode
from quadstep.protocol.cubic_run import CubicSegments
from quadstep.protocol.frame_choice import RUN_FRAMES, FrameChoice, frame_choice
from quadstep.protocol.messages import Ack, ErrorReport, IdentifyReply, queue_slots
from quadstep.protocol.frames import next_frame, run_limit
from quadstep.kernel.fixed import D
from quadstep.protocol.segment_run import RunChain, Segments, pack
from test_avr_steps import AXES, run_both


class _Run:
    def __init__(self, segments: list[Segment]) -> None:
        self.segments = segments

    def segment(self, i: int) -> Segment:
        return self.segments[i]


def frames(run: list[Segment], limit: int, choice: FrameChoice = RUN_FRAMES) -> list:
    """The run as a motion sends it to a board that takes `choice`: runs once the chain is known."""
    chain, out, index = RunChain(4), [], 0
    while index < len(run):
        message = next_frame(_Run(run), index, len(run), chain, limit, choice.cubic_runs, choice.quadratic_runs)
        out.append(message)
        index += queue_slots(message)
    return out


def send_packed(url: str, runs: list[list[Segment]]) -> StatusReport:
    """Every run sent to the board at `url` in every kind of run its firmware takes (one frame with several
    segments among them)."""
    with Link.open(url) as link:
        status = link.status()
        identity = link.identity
        assert identity is not None
        choice = FrameChoice(
            quadratic_runs=bool(identity.capabilities & Capability.SEGMENTS),
            cubic_runs=bool(identity.capabilities & Capability.CUBIC_RUNS),
        )
        sent = [frames(run, run_limit(identity.queue_capacity), choice) for run in runs]
        assert any(isinstance(m, (Segments, CubicSegments)) and len(m) > 1 for run in sent for m in run)
        for run in sent:
            for message in run:
                link.send(message, timeout=60)
            status = link.wait_idle(timeout=120)
    return status


def test_uno_runs_sent_in_cubic_segments_frames_match_emulator_and_model(avr_build: None, tmp_path: Path,
                                                                         start_emulator) -> None:  # noqa: ANN001
    runs = avr_scenarios.quadratic_into_cubic(AXES["uno"])
    run_both("uno", runs, tmp_path, start_emulator, send=send_packed)
    uno = FrameChoice(quadratic_runs=False, cubic_runs=True)
    plain = sum(len(encode(s, 0)) for run in runs for s in run)
    packed = sum(len(encode(m, 0)) for run in runs for m in frames(run, run_limit(14), uno))
    assert packed < plain


def test_the_uno_takes_no_segments_frames(avr_build: None, tmp_path: Path) -> None:
    """Its IDENTIFY says so, and a SEGMENTS frame sent anyway is refused as a type it does not know: nothing of
    it runs, and the segments before it run as sent."""
    b = avr_scenarios.ChainBuilder(3)
    ramp_up, ramp_down = {a: (1, 0, D // 2) for a in range(3)}, {a: (1, D // 2, 0) for a in range(3)}
    sent = [b.segment(400, ramp_up), b.segment(400, ramp_down)]
    chain = RunChain(4)
    for segment in sent:
        chain.follow(segment)
    more = [b.segment(400, ramp_up), b.segment(400, ramp_down)]
    packed = pack(more, chain)
    assert isinstance(packed, Segments) and len(packed) == 2
    data = b"\x00" + encode(Identify(), 0) + encode(sent[0], 0) + encode(sent[1], 1) + encode(packed, 2)
    outputs = Outputs.in_dir(tmp_path)
    stats = run_input(data, outputs, tmp_path / "replies.bin")
    replies = [item.message for item in Decoder("to_host", axis_count=3).feed((tmp_path / "replies.bin").read_bytes())
               if hasattr(item, "message")]
    identity = next(r for r in replies if isinstance(r, IdentifyReply))
    assert not identity.capabilities & Capability.SEGMENTS
    assert identity.capabilities & Capability.CUBIC_RUNS
    assert frame_choice(identity) == FrameChoice(quadratic_runs=False, cubic_runs=True)
    errors = [r for r in replies if isinstance(r, ErrorReport)]
    assert [(e.code, e.frame_seq) for e in errors] == [(ErrorCode.UNKNOWN_TYPE, 2)]
    assert [(a.next_seq, a.reason) for a in replies if isinstance(a, Ack) and a.reason != AckReason.SPACE] == [
        (1, AckReason.ACCEPTED), (2, AckReason.ACCEPTED)
    ]
    expected = predict(sent, axis_count=3)
    assert len(expected.steps) > 0 and np.array_equal(outputs.load_trace(), expected.steps)
    assert stats["motion"]["steps"] == expected.per_axis_steps


def test_mega_runs_sent_as_segments_match_emulator_and_model(avr_build: None, tmp_path: Path,
                                                             start_emulator) -> None:  # noqa: ANN001
    run_both("mega", avr_scenarios.random_runs(AXES["mega"], seed=11, runs=2), tmp_path, start_emulator,
             send=send_packed)
