"""Bytes on the wire against the G-code they replace (exact counts, so asserted): CAM-shaped jobs sent in SEGMENTS
runs (to a board that takes runs faster than single segments, as the emulator does) take fewer bytes than their
G-code text, and about a third of one SEGMENT a frame, which is what an Uno is sent (protocol/frame_choice.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from quadstep.coordinates import WorkCoordinates
from quadstep.gcode import parse_gcode
from quadstep.job import Job
from quadstep.protocol.frame_choice import RUN_FRAMES, SINGLE_FRAMES
from quadstep.planner.plan import plan_program

BENCH = Path(__file__).resolve().parents[1] / "bench"
sys.path.insert(0, str(BENCH))

import bench_wire  # noqa: E402
import cam_jobs  # noqa: E402


# The engraving whole (the tightest: three segments a move, half of them at corners); the others, whose
# margins are wide (0.86 and 0.69 whole, tests/bench/bench_wire.py), cut short to keep the suite quick.
@pytest.mark.slow
@pytest.mark.parametrize(("name", "lines"), [("pocket", 3000), ("engraving", 16_000), ("four_axis", 3000)])
def test_a_cam_job_takes_fewer_bytes_on_the_wire_than_its_gcode(name: str, lines: int) -> None:
    text = cam_jobs.JOBS[name](lines)
    names = "XYZA" if name == "four_axis" else "XYZ"
    config = bench_wire.machine(names, None)
    program = parse_gcode(text, config.axis_names, (0.0,) * len(names), config.arc_tolerance, True)
    job = Job(path=Path(name), program=program, plan=plan_program(program, config), coordinates=WorkCoordinates())
    wire, single = job.wire_bytes(RUN_FRAMES), job.wire_bytes(SINGLE_FRAMES)
    assert wire <= len(text.encode()), (wire, len(text.encode()))
    assert wire * 2.5 < single
    assert job.wire_bytes() == single  # an Uno takes one SEGMENT a frame faster than SEGMENTS


def test_an_scurve_job_in_cubic_segments_frames_takes_about_half_the_bytes() -> None:
    """S-curve plans go out in CUBIC_SEGMENTS frames: the engraving's first 1,000 lines in about half the bytes
    of one CUBIC_SEGMENT a frame (the whole: 1.74 times the G-code against 3.39; docs/BENCHMARKS.md)."""
    text = cam_jobs.JOBS["engraving"](1000)
    config = bench_wire.machine("XYZ", 20000.0)
    program = parse_gcode(text, config.axis_names, (0.0,) * 3, config.arc_tolerance, True)
    job = Job(path=Path("engraving"), program=program, plan=plan_program(program, config), coordinates=WorkCoordinates())
    wire, single = job.wire_bytes(RUN_FRAMES), job.wire_bytes(SINGLE_FRAMES)
    assert wire < 2 * len(text.encode()) and wire * 1.8 < single, (wire, single, len(text.encode()))
    assert job.wire_bytes() == wire
