"""The motion of a sender's queued lines, as the front door estimates it to start a job: each move
at its feed, rapids at the slowest axis's top speed, dwells; enough once it outlasts the end a
running job keeps back from the board and the floor fed before it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.grbl.queued_motion import QueuedMotion
from quadstep.machine.open_end import FLOOR_S, kept_back_s

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def items(text: str) -> list:
    return parse_gcode(text, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance).items


def test_moves_at_their_feed_rapids_at_the_slowest_top_speed_and_dwells() -> None:
    motion = QueuedMotion(CONFIG)
    slowest = min(axis.max_speed for axis in CONFIG.axes)
    # the first move's start is not known: it counts from the second on
    motion.add(items("G1 X3 Y4 F600\nX6 Y8\nG0 X6 Y18\nG4 P0.5\n"))
    assert motion.seconds == pytest.approx(5 / 10 + 10 / slowest + 0.5)
    motion.clear()
    assert motion.seconds == 0.0
    motion.add(items("G1 X0 Y0 F1200\n"))  # from the last target before the clear, at 20 mm/s
    assert motion.seconds == pytest.approx(math.dist((6, 18), (0, 0)) / 20)


def test_enough_once_the_lines_outlast_the_kept_back_end_and_the_floor() -> None:
    motion = QueuedMotion(CONFIG)
    start_s = kept_back_s(CONFIG) + FLOOR_S
    chords = items("G1 F600\n" + "".join(f"X{0.05 * k:.2f}\n" for k in range(400)))  # 5 ms each
    added = 0
    while not motion.enough:
        motion.add(chords[added : added + 1])
        added += 1
    assert (added - 2) * 0.005 < start_s <= (added - 1) * 0.005 + 1e-9
    assert 0.6 < start_s < 0.7  # the router: 0.37 s kept back, 0.25 s fed before it
