"""A jerk-limited G-code job, planned by the host as cubic segments, runs on the real AVR firmware in simavr
step for step as on the emulator and as the host predicts."""

from __future__ import annotations

from pathlib import Path

import pytest

from test_avr_segments import send_packed
from test_avr_steps import run_both

from quadstep.config import parse_config
from quadstep.gcode import parse_gcode
from quadstep.planner.plan import plan_program

JOB = """G21 G90 G17
G1 X3 Y1 F1800
G2 X5 Y3 I0 J2 F1200
G1 X5.2 Y6 Z-0.5 F2400
G3 X2 Y6 R1.7
G0 X0 Y0 Z0
"""


def scurve_segments() -> list:
    config = parse_config({
        "tick_hz": 32000,
        "axes": [{"name": n, "steps_per_mm": 400, "max_speed": 40, "max_accel": 800, "max_jerk": 40000,
                  "travel_min": -100, "travel_max": 100} for n in "XYZ"],
    })
    program = parse_gcode(JOB, config.axis_names, (0.0, 0.0, 0.0), config.arc_tolerance)
    plan = plan_program(program, config)
    segments = list(plan.segments.segments())
    assert len(segments) > 40 and plan.end == (0, 0, 0)
    return segments


def test_uno_runs_an_scurve_job_as_predicted(avr_build: None, tmp_path: Path, start_emulator) -> None:
    run_both("uno", [scurve_segments()], tmp_path, start_emulator)


@pytest.mark.parametrize("board", ["uno", "mega"])
def test_an_scurve_job_sent_in_cubic_segments_frames_runs_as_predicted(board: str, avr_build: None, tmp_path: Path,
                                                                       start_emulator) -> None:
    """The same job as a motion sends it: its cubic segments several to a CUBIC_SEGMENTS frame."""
    run_both(board, [scurve_segments()], tmp_path, start_emulator, send=send_packed)
