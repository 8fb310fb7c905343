"""CUBIC_SEGMENTS (PROTOCOL.md §5.2): the records' meaning is the independent reference's (protocol/vectors.json's
expands_to, which the firmware's C checks too); any chained cubic stream packed into frames reads back as itself
from the chain each frame starts on, and means the same when sent again; a frame never outgrows MAX_FRAME; a
jerk-limited move's phases take a few bytes each."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from quadstep.protocol import MAX_FRAME, CubicSegment, Segment, encode
from quadstep.kernel.motion import AxisMove, CubicAxis
from quadstep.protocol.codec import decode
from quadstep.kernel.fixed import SIGMA
from quadstep.kernel.cubic_chain import CubicChain, CubicRefused
from quadstep.protocol.cubic_run import CubicSegments, SpeedChain, expand, pack
from quadstep.protocol.frames import next_frame
from quadstep.protocol.messages import queue_slots
from quadstep.protocol.segment_run import RunChain

from frame_helpers import ListSource, read_frame

REPO = Path(__file__).resolve().parents[2]
VECTORS = [v for v in json.loads((REPO / "protocol" / "vectors.json").read_text())["vectors"]
           if v["message"] is not None and v["message"]["type"] == "CUBIC_SEGMENTS"]


def meaning(segment: CubicSegment) -> tuple:
    """What a cubic segment does: n, and per axis its set and its jerk (an axis named with jerk 0 and no set
    is one not named)."""
    axes = tuple((a.axis, (a.speed, a.accel, a.direction) if a.speed is not None else None, a.jerk or 0)
                 for a in segment.axes if a.speed is not None or a.jerk)
    return segment.n, axes


def test_there_are_cubic_segments_vectors() -> None:
    assert len(VECTORS) >= 3
    codes = {c for v in VECTORS for r in v["message"]["records"] for c in r["codes"]}
    assert codes == {0, 1, 2, 3} and any("accels" in r for v in VECTORS for r in v["message"]["records"])


@pytest.mark.parametrize("vector", VECTORS, ids=lambda v: v["name"])
def test_each_vector_means_what_the_reference_says(vector: dict) -> None:
    message = decode(bytes.fromhex(vector["frame"]), "to_firmware", vector.get("axis_count", 4)).message
    assert isinstance(message, CubicSegments)
    got = expand(message.records, CubicChain(4))
    assert [meaning(s) for s in got] == [meaning(CubicSegment.model_validate(s)) for s in vector["expands_to"]]


@st.composite
def cubic_streams(draw: st.DrawFn) -> list[Segment | CubicSegment]:
    """A stream as the S-curve planner and the backlash stage make them: a quadratic segment at rest first,
    then cubic segments whose jerks repeat and negate earlier ones, with sets (corners, landings, reversals)
    and cruises; every one valid against the chain it meets."""
    axes = draw(st.integers(1, 4))
    chain = CubicChain(axes)
    out: list[Segment | CubicSegment] = [Segment(n=1, axes=tuple(AxisMove(axis=a, direction=1, v0=0, vn=0, r=0)
                                                                  for a in range(axes)))]
    jerks = [0] * axes
    for _ in range(draw(st.integers(1, 40))):
        named = []
        for a in range(axes):
            kind = draw(st.integers(0, 5))
            jerk = [0, jerks[a], -jerks[a], draw(st.integers(-3000, 3000)), jerks[a], -jerks[a]][kind]
            if draw(st.integers(0, 4)) == 0:
                state = chain.axes[a]
                speed = draw(st.one_of(st.integers(0, SIGMA // 2), st.integers(max(0, state.i - 5000),
                                                                                 max(0, min(SIGMA - 1, state.i + 5000)))))
                accel = draw(st.sampled_from([0, 0, 0, draw(st.integers(-20000, 20000))]))
                named.append(CubicAxis(axis=a, speed=speed, accel=accel, direction=draw(st.sampled_from([1, -1])),
                                       jerk=jerk or None))
            elif jerk:
                named.append(CubicAxis(axis=a, jerk=jerk))
        segment = CubicSegment(n=draw(st.one_of(st.integers(1, 300), st.integers(1, 65535))), axes=tuple(named))
        trial = chain.copy()
        try:
            trial.advance(segment)
        except CubicRefused:  # one the firmware would refuse: stop every axis instead
            segment = CubicSegment(n=segment.n, axes=tuple(CubicAxis(axis=a, speed=0) for a in range(axes)))
        chain.advance(segment)
        for a in segment.axes:
            jerks[a.axis] = a.jerk or jerks[a.axis]
        out.append(segment)
    return out


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(cubic_streams(), st.integers(2, 16))
def test_packed_frames_read_back_as_the_stream(stream: list[Segment | CubicSegment], limit: int) -> None:
    chain, board, index = RunChain(4), CubicChain(4), 0
    runs = 0
    while index < len(stream):
        before = board.copy()
        message = next_frame(ListSource(stream), index, len(stream), chain, limit)
        frame = encode(message, index & 0xFF)
        assert len(frame) <= MAX_FRAME + 2  # COBS code byte and delimiter
        got = read_frame(frame)
        if isinstance(got, CubicSegments):
            runs += 1
            assert 1 <= len(got) <= limit
            meant = expand(got.records, board)
            assert [meaning(s) for s in meant] == [meaning(s) for s in stream[index : index + len(meant)]]  # type: ignore[arg-type]
            assert [meaning(s) for s in expand(got.records, before)] == [meaning(s) for s in meant]  # sent again
        elif isinstance(got, CubicSegment):
            assert meaning(got) == meaning(stream[index])  # type: ignore[arg-type]
            board.advance(got)
        else:
            assert got == stream[index]
            board.follow_quadratic(got, {a.axis: 0 for a in got.axes})  # at rest: no steps
        index += queue_slots(message)
    assert runs > 0  # after the quadratic segment the chain is known: cubic ones go in runs


def test_a_set_that_cannot_start_from_the_chain_goes_alone() -> None:
    """An axis whose speed the host does not know (before the motion's first segment) cannot take a set as a
    change: the segment goes as a CUBIC_SEGMENT, and the runs start once the chain is known."""
    ramp = [CubicSegment(n=100, axes=(CubicAxis(axis=0, speed=1000, jerk=5),)), CubicSegment(n=100, axes=(CubicAxis(axis=0, jerk=-5),))]
    chain = RunChain(2)
    first = next_frame(ListSource(list(ramp)), 0, 2, chain, 8)
    assert isinstance(first, CubicSegment)
    assert chain.speeds is not None and chain.speeds.i[1] is None and chain.speeds.i[0] == 1000 + 100 * 0 + 4950 * 5
    assert isinstance(next_frame(ListSource(list(ramp)), 1, 2, chain, 8), CubicSegments)


def test_a_seven_phase_move_takes_a_few_bytes_a_phase() -> None:
    """Three axes from rest, set to their directions with jerks J, then the jerks negated, then a cruise: the
    first phase is 12 bytes, one that negates (or repeats) the jerks 3, a cruise 3 (n in two bytes each);
    as CUBIC_SEGMENTs 36, 15 and 9 bytes on the wire, each its own frame."""
    jerk = {0: 300, 1: -200, 2: 40}
    speeds = SpeedChain.at_rest(3)
    first = CubicSegment(n=400, axes=tuple(CubicAxis(axis=a, speed=0, direction=-1 if j < 0 else 1, jerk=abs(j))
                                           for a, j in jerk.items()))
    phases = [CubicSegment(n=400, axes=tuple(CubicAxis(axis=a, jerk=sign * abs(j)) for a, j in jerk.items()))
              for sign in (-1,)]
    cruise = CubicSegment(n=2000)
    packed = pack([first, *phases, cruise], speeds)
    assert packed is not None
    sizes = [len(r.pack()) for r in packed.records]
    assert sizes == [1 + 2 + 1 + 3 + 5, 3, 3]  # codes, n, the sets byte and three changes of 0, three jerks
    assert [len(encode(s, 0)) for s in (first, *phases, cruise)] == [36, 15, 9]
    assert len(encode(packed, 0)) == sum(sizes) + 6  # type, seq, CRC, COBS code byte, delimiter
