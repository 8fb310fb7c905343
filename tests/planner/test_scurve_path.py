"""A path planned as S-curves stays on the G-code's polyline: every axis of a move keeps the path's
proportion, to the rounding of its ramps' jerks and the stepper's half step, all the way along, as
at constant acceleration.

Each axis lands on its target exactly; landing one by a ramp's jerk alone (a few jerk units more on
the slower axis, its cruise a little slower to make up) left the line by up to 109 steps mid-move in
these lines, and 163 in the corpus's parking moves. The cruise's speed, set where it begins, lands
each axis now (planner/scurve.py).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from path_fidelity import lines, steps_off_the_path

from quadstep.config import MachineConfig, load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.job import load_job

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
SCURVE = ROUTER.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in ROUTER.axes)}
)
CORPUS = REPO / "tests" / "gcode" / "corpus" / "grbl"
# the stepper's half step on three axes (0.87), and about one more for the ramps' rounded jerks
MOST_OFF_THE_PATH = 2.5


def off_the_path(gcode: str, config: MachineConfig, tmp_path: Path) -> float:
    path = tmp_path / "job.gcode"
    path.write_text(gcode)
    return steps_off_the_path(load_job(path, config).plan)


def test_a_3_to_1_diagonal_keeps_its_proportion(tmp_path: Path) -> None:
    # 18.7 steps off mid-way before: Y's last ramp 187 jerk units to X's 522, its cruise 3.015:1
    assert off_the_path("G21 G90 F2400\nG1 X30 Y10\n", SCURVE, tmp_path) < 1.0


@pytest.mark.parametrize("gcode", lines(1, 12) + lines(2, 12))
def test_any_straight_line_stays_on_it(gcode: str, tmp_path: Path) -> None:
    assert off_the_path(gcode, SCURVE, tmp_path) <= MOST_OFF_THE_PATH


@pytest.mark.parametrize(
    "name", ["fusion-grbl-contour.nc", "g28-g30-parking.nc", "flatcam-isolation.nc", "helix-bore.nc"]
)
def test_cam_jobs_stay_on_their_polylines(name: str) -> None:
    """Contours, parking moves, isolation routing and a helix from the corpus, with G54 at the stock's
    corner (tests/gcode/test_corpus.py)."""
    coordinates = WorkCoordinates()
    for axis, mm in zip("XYZ", (50.0, 50.0, -20.0)):
        coordinates.set_offset(1, axis, mm)
    plan = load_job(CORPUS / name, SCURVE, coordinates=coordinates).plan
    assert steps_off_the_path(plan) <= MOST_OFF_THE_PATH
