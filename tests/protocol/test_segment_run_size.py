"""The wire count without frames equals the bytes of the frames a plan would send, built and
encoded one by one (frames.next_frame, codec.encode): from a quadratic plan's arrays on CAM-shaped
jobs and on random segments made to hit every record kind (REPEAT, a new axes byte, start,
residual, cruise, MIRROR), and from a jerk-limited plan's cubic segments on the same jobs."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from quadstep.gcode import parse_gcode
from quadstep.planner.plan import plan_program
from quadstep.planner.segments import SegmentArrays
from quadstep.planner.stream import Stream
from quadstep.protocol.codec import encode
from quadstep.protocol.cubic_run_size import cubic_wire_bytes
from quadstep.protocol.frames import next_frame
from quadstep.protocol.messages import queue_slots
from quadstep.protocol.segment_run import RunChain
from quadstep.protocol.segment_run_size import quadratic_wire_bytes

BENCH = Path(__file__).resolve().parents[1] / "bench"
sys.path.insert(0, str(BENCH))

import bench_wire  # noqa: E402
import cam_jobs  # noqa: E402

LIMITS = [0, 1, 2, 7, 8, 16]


def encoded_bytes(segments: SegmentArrays | Stream, limit: int) -> int:
    """Every frame built and encoded, as a motion sends them."""
    chain = RunChain(segments.axis_count)
    total = index = 0
    while index < len(segments):
        message = next_frame(segments, index, len(segments), chain, limit)
        total += len(encode(message, 0))
        index += queue_slots(message)
    return total


@pytest.mark.slow
@pytest.mark.parametrize("name", ["pocket", "engraving", "four_axis"])
def test_a_cam_jobs_count_equals_its_encoded_frames(name: str) -> None:
    text = cam_jobs.JOBS[name](1500)
    names = "XYZA" if name == "four_axis" else "XYZ"
    config = bench_wire.machine(names, None)
    program = parse_gcode(text, config.axis_names, (0.0,) * len(names), config.arc_tolerance, True)
    segments = plan_program(program, config).segments
    assert isinstance(segments, SegmentArrays) and len(segments) > 1000
    for limit in LIMITS:
        counted = quadratic_wire_bytes(segments.numpy(), segments.axis_count, limit)
        assert counted == encoded_bytes(segments, limit), limit


@st.composite
def segment_arrays(draw: st.DrawFn) -> SegmentArrays:
    """Segments from small pools of values, so that shapes repeat, residuals chain or not, speeds
    change by small and large amounts and axes come and go."""
    count = draw(st.integers(1, 4))
    out = SegmentArrays(count)
    speeds = st.sampled_from([0, 1, 63, 64, 200, 2000, 4096])
    for _ in range(draw(st.integers(1, 60))):
        axes = draw(st.integers(1, (1 << count) - 1))
        axes |= draw(st.integers(0, 15)) << 4 & axes << 4
        v0 = [draw(speeds) if axes >> a & 1 else 0 for a in range(count)]
        vn = [
            draw(st.sampled_from([v0[a], draw(speeds)])) if axes >> a & 1 else 0
            for a in range(count)
        ]
        r = [
            draw(st.sampled_from([0, 5, -70, 4095, -4096])) if axes >> a & 1 else 0
            for a in range(count)
        ]
        for _ in range(draw(st.sampled_from([1, 1, 2, 5]))):
            out.append(draw(st.sampled_from([1, 7, 300, 1022])), axes, v0, vn, r, 0)
    return out


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(segment_arrays(), st.sampled_from(LIMITS))
def test_random_segments_count_equals_their_encoded_frames(
    segments: SegmentArrays, limit: int
) -> None:
    counted = quadratic_wire_bytes(segments.numpy(), segments.axis_count, limit)
    assert counted == encoded_bytes(segments, limit)


@pytest.mark.parametrize("name", ["pocket", "engraving", "four_axis"])
def test_an_scurve_jobs_count_equals_its_encoded_frames(name: str) -> None:
    text = cam_jobs.JOBS[name](600)
    names = "XYZA" if name == "four_axis" else "XYZ"
    config = bench_wire.machine(names, 20000.0)
    program = parse_gcode(text, config.axis_names, (0.0,) * len(names), config.arc_tolerance, True)
    segments = plan_program(program, config).segments
    assert isinstance(segments, Stream) and len(segments) > 500
    for limit in LIMITS:
        counted = cubic_wire_bytes(segments.extra, segments.axis_count, limit)
        assert counted == encoded_bytes(segments, limit), limit
