"""A straight line planned as S-curves stays on its line: every axis of a move keeps the path's
proportion, to the rounding of its ramps' jerks and the stepper's half step, all the way along.

Each axis lands on its target exactly; landing one by a ramp's jerk alone (a few jerk units more on
the slower axis, its cruise a little slower to make up) left the line by up to 109 steps mid-move in
these lines. The cruise's speed, set where it begins, lands each axis now (planner/scurve.py).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from straight_lines import lines, steps_off_the_line

from quadstep.config import load_config

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
SCURVE = ROUTER.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in ROUTER.axes)}
)
# the stepper's half step on three axes (0.87), and about one more for the ramps' rounded jerks
MOST_OFF_THE_LINE = 2.5


def test_a_3_to_1_diagonal_keeps_its_proportion() -> None:
    # 18.7 steps off mid-way before: Y's last ramp 187 jerk units to X's 522, its cruise 3.015:1
    assert steps_off_the_line("G21 G90 F2400\nG1 X30 Y10\n", SCURVE) < 1.0


@pytest.mark.parametrize("gcode", lines(1, 12) + lines(2, 12))
def test_any_straight_line_stays_on_it(gcode: str) -> None:
    assert steps_off_the_line(gcode, SCURVE) <= MOST_OFF_THE_LINE
