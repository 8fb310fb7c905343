"""SEGMENTS (PROTOCOL.md §5.2): the records' meaning is the independent reference's (protocol/vectors.json's
expands_to, which the firmware's C checks too); any chained stream packed into frames reads back as itself from
the chain each frame starts on; a frame never outgrows MAX_FRAME; a resent frame means what it meant."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from quadstep.protocol import MAX_FRAME, CubicSegment, Segment, encode
from quadstep.kernel.motion import AxisMove
from quadstep.protocol.codec import decode
from quadstep.protocol.frames import next_frame
from quadstep.protocol.messages import queue_slots
from quadstep.protocol.segment_run import RunChain, SegmentRecord, Segments, expand, pack
from quadstep.protocol.wire import FieldFault

from frame_helpers import ListSource, read_frame

REPO = Path(__file__).resolve().parents[2]
VECTORS = [v for v in json.loads((REPO / "protocol" / "vectors.json").read_text())["vectors"]
           if v["message"] is not None and v["message"]["type"] == "SEGMENTS"]


def test_there_are_segments_vectors() -> None:
    assert len(VECTORS) >= 3 and any(any(r.get("mirror") for r in v["message"]["records"]) for v in VECTORS)


@pytest.mark.parametrize("vector", VECTORS, ids=lambda v: v["name"])
def test_each_vector_means_what_the_reference_says(vector: dict) -> None:
    message = decode(bytes.fromhex(vector["frame"]), "to_firmware", vector.get("axis_count", 4)).message
    assert isinstance(message, Segments)
    got = expand(message.records, RunChain.at_rest(4))
    assert got == [Segment.model_validate(s) for s in vector["expands_to"]]


def test_a_record_that_leaves_the_speed_range_is_refused_by_field_and_axis() -> None:
    records = (SegmentRecord(n=10, axes=0x03, change=(5, 100)), SegmentRecord(n=10, change=(0, -101)))
    with pytest.raises(FieldFault) as refused:
        expand(records, RunChain.at_rest(3))
    assert (refused.value.field.name, refused.value.axis) == ("VN", 1)


@st.composite
def chained_streams(draw: st.DrawFn) -> list[Segment]:
    """A stream as a planner makes it: each axis's speed and residual carried from segment to segment, with
    stops, reversals, corners (speed jumps), dwells and repeats."""
    axes = draw(st.integers(1, 4))
    chain = RunChain.at_rest(axes)
    speed = [0] * axes
    out: list[Segment] = []
    for _ in range(draw(st.integers(1, 40))):
        if out and draw(st.integers(0, 5)) == 0:  # the same segment again
            moves = [AxisMove(axis=a.axis, direction=a.direction, v0=a.v0, vn=a.vn,
                              r=a.direction * chain.residual[a.axis]) for a in out[-1].axes]
            segment = Segment(n=out[-1].n, axes=tuple(moves))
        else:
            moves = []
            for a in range(axes):
                if draw(st.integers(0, 3)) == 0:
                    continue
                direction = draw(st.sampled_from([1, -1]))
                v0 = speed[a] if draw(st.integers(0, 3)) else draw(st.integers(0, 4095))
                vn = draw(st.one_of(st.just(v0), st.integers(0, 4095), st.integers(max(0, v0 - 40), min(4095, v0 + 40))))
                moves.append(AxisMove(axis=a, direction=direction, v0=v0, vn=vn, r=direction * chain.residual[a]))
            segment = Segment(n=draw(st.integers(1, 1022)), axes=tuple(moves))
        chain.follow(segment)
        speed = [0] * axes
        for m in segment.axes:
            speed[m.axis] = m.vn
        out.append(segment)
    return out


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(chained_streams(), st.integers(2, 16))
def test_packed_frames_read_back_as_the_stream(stream: list[Segment], limit: int) -> None:
    axes = max((a.axis for s in stream for a in s.axes), default=0) + 1
    chain, board, index = RunChain(4), RunChain.at_rest(4), 0
    while index < len(stream):
        before = board.copy()
        message = next_frame(ListSource(stream), index, len(stream), chain, limit)
        frame = encode(message, index & 0xFF)
        assert len(frame) <= MAX_FRAME + 2  # COBS code byte and delimiter
        got = read_frame(frame)
        if isinstance(got, Segments):
            assert 1 <= len(got) <= limit
            meant = expand(got.records, board)
            assert meant == stream[index : index + len(meant)]
            assert expand(got.records, before) == meant  # sent again, it means the same
        else:
            assert got == stream[index]
            board.follow(got)
        index += queue_slots(message)
    assert axes <= 4


@pytest.mark.parametrize("cubic_runs", [True, False])
def test_after_a_cubic_segment_the_next_frame_states_everything(cubic_runs: bool) -> None:
    """A cubic segment goes in CUBIC_SEGMENTS where the board has it (the quadratic segments before told the
    host every axis's speed), else alone; either way the quadratic grid is unknown after it."""
    quad = Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=100, vn=100, r=0),))
    stream: list[Segment | CubicSegment] = [quad, quad, CubicSegment(n=50), quad, quad]
    chain = RunChain(3)
    kinds = []
    index = 0
    while index < len(stream):
        message = next_frame(ListSource(stream), index, len(stream), chain, 8, cubic_runs)
        kinds.append(type(message).__name__)
        index += queue_slots(message)
    cubic = "CubicSegments" if cubic_runs else "CubicSegment"
    assert kinds == ["Segment", "Segments", cubic, "Segment", "Segments"]


def test_a_chained_cruise_is_two_bytes_and_a_repeat_one() -> None:
    chain = RunChain.at_rest(2)
    first = Segment(n=600, axes=(AxisMove(axis=0, direction=1, v0=0, vn=1000, r=0),
                                 AxisMove(axis=1, direction=-1, v0=0, vn=500, r=0)))
    chain_after = chain.copy()
    chain_after.follow(first)
    cruise = Segment(n=600, axes=tuple(AxisMove(axis=a.axis, direction=a.direction, v0=a.vn, vn=a.vn,
                                                r=a.direction * chain_after.residual[a.axis]) for a in first.axes))
    chain_after.follow(cruise)
    again = Segment(n=600, axes=tuple(AxisMove(axis=a.axis, direction=a.direction, v0=a.v0, vn=a.vn,
                                               r=a.direction * chain_after.residual[a.axis]) for a in cruise.axes))
    message = pack([first, cruise, again], chain)
    assert message is not None and len(message) == 3
    sizes = [len(Segments(records=(r,)).records[0].pack(2)) for r in message.records]
    assert sizes[1:] == [2, 1]
