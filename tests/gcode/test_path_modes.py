"""G61 and G64: exact stop at every corner, or corners within a path tolerance (P) by the cornering rule."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.gcode import parse_gcode
from quadstep.planner.lookahead import junction_speeds
from quadstep.planner.moves import build_moves

ROUTER = Path(__file__).resolve().parents[2] / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
ZIGZAG = "G1 X10 Y0 F1200\nX20 Y5\nX30 Y0\nX40 Y5\n"  # three 27° corners


def corner_speeds(text: str) -> list[float]:
    program = parse_gcode(text, CONFIG.axis_names, [0.0, 0.0, 0.0])
    table = build_moves(program, CONFIG, (0, 0, 0))
    return junction_speeds(table, CONFIG)[1:-1]


def test_g61_stops_at_every_corner() -> None:
    assert corner_speeds("G61\n" + ZIGZAG) == [0.0, 0.0, 0.0]
    assert corner_speeds("G61.1\n" + ZIGZAG) == [0.0, 0.0, 0.0]


def test_g64_without_p_is_the_configured_cornering() -> None:
    assert corner_speeds("G64\n" + ZIGZAG) == corner_speeds(ZIGZAG)
    assert all(v > 0 for v in corner_speeds(ZIGZAG))


@pytest.mark.parametrize("tolerance", [0.001, 0.05])
def test_g64_p_is_the_junction_deviation(tolerance: float) -> None:
    """The rule's speed grows with the square root of the deviation: P in place of junction_deviation."""
    tight, loose = corner_speeds(ZIGZAG), corner_speeds(f"G64 P{tolerance}\n" + ZIGZAG)
    ratio = (tolerance / CONFIG.junction_deviation) ** 0.5
    cap = 20 / CONFIG.tick_hz  # the feed, 1200 mm/min, in mm/tick
    for a, b in zip(tight, loose):
        assert b == pytest.approx(min(cap, a * ratio), rel=1e-6)


def test_the_mode_holds_until_changed() -> None:
    speeds = corner_speeds("G61\nG1 X10 Y0 F1200\nX20 Y5\nG64\nX30 Y0\nX40 Y5\n")
    assert speeds[0] == 0.0 and speeds[1] > 0 and speeds[2] > 0


def test_g64_in_inches() -> None:
    assert corner_speeds("G20 G64 P0.002\nG21\n" + ZIGZAG) == corner_speeds("G64 P0.0508\n" + ZIGZAG)
