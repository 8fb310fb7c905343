"""Jobs that would be planned without end are refused before planning, naming the line, the feed
or accel that makes them so, and the bound: a job moves and dwells for at most 2^32 ticks (the
board's motion tick counter)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.planner.limits import MAX_JOB_TICKS, check_duration, move_ticks
from quadstep.planner.lookahead import junction_speeds
from quadstep.planner.moves import build_moves
from quadstep.planner.program import JobError, LinearMove, Program

REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")  # 32 kHz: 2^32 ticks are 37.3 h
BOUND = ("a job may move for at most 37.3 h (134218 s: 2^32 ticks, the range of the board's "
         "motion tick counter, at tick_hz 32000)")


def refusal(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(JobError) as caught:
        load_job(path, ROUTER)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message.removeprefix(f"{path}: ")


def test_a_feed_of_1e_minus_10_mm_per_min_is_refused_with_the_slowest_feed(tmp_path: Path) -> None:
    assert refusal(tmp_path, "job.gcode", "G21 G90\nG1 X10 F0.0000000001\n") == (
        "line 2: its feed, 1.67e-12 mm/s (1e-10 mm/min), would make this 10 mm move last at least "
        "6e+12 s: the slowest feed for it is 7.45e-05 mm/s (0.00447 mm/min); " + BOUND)


@pytest.mark.parametrize("share", [0.99, 1.01])
def test_the_slowest_feed_named_is_the_bound(share: float) -> None:
    """A 0.25 mm move (100 steps) a little slower than the slowest feed for it is refused, a little
    faster is not (checked, not planned: planned, it is 4 million segments)."""
    feed = 0.25 / (MAX_JOB_TICKS / 32000) * share  # mm/s
    program = Program(items=[LinearMove(2, (0.25, 0.0, 0.0), feed)], lines=2)
    table = build_moves(program, ROUTER, (0, 0, 0))
    entry = junction_speeds(table, ROUTER)
    if share < 1:
        with pytest.raises(JobError, match="the slowest feed for it is 1.86e-06 mm/s"):
            check_duration(table, ROUTER, "line", entry)
    else:
        check_duration(table, ROUTER, "line", entry)


@pytest.mark.parametrize(("field", "message"), [
    ("feed", "move 1: its feed, 1e-300 mm/s (6e-299 mm/min), would make this 10 mm move last at "
             "least 1e+301 s: the slowest feed for it is 7.45e-05 mm/s (0.00447 mm/min)"),
    ("accel", "move 1: its accel, 1e-300 mm/s² along the path, would make this 10 mm move last at "
              "least 6.32e+150 s"),
])
def test_a_feed_or_accel_of_1e_minus_300_in_a_move_file_is_refused(tmp_path: Path, field: str,
                                                                   message: str) -> None:
    move = {"to": {"X": 10}, "feed": 10, field: 1e-300}
    text = json.dumps({"moves": [move]})
    assert refusal(tmp_path, "moves.json", text) == f"{message}; {BOUND}"


def test_a_slow_accel_between_moves_at_speed_is_no_wait(tmp_path: Path) -> None:
    """A move that need not change speed takes no longer for its accel: only what the job must do
    counts."""
    moves = [{"to": {"X": 10}, "feed": 10}, {"to": {"X": 20}, "feed": 10, "accel": 1e-300},
             {"to": {"X": 30}, "feed": 10}]
    path = tmp_path / "moves.json"
    path.write_text(json.dumps({"moves": moves}))
    assert load_job(path, ROUTER).plan.duration_s < 4


def test_ten_thousand_dwells_of_an_hour_are_refused_where_they_pass_the_bound(
        tmp_path: Path) -> None:
    # 37 hours fit in 37.3 h, the 38th passes it
    assert refusal(tmp_path, "dwells.gcode", "G4 P3600\n" * 10_000) == (
        f"line 38: the job's motion and dwells up to here last 38.0 h; {BOUND}")


def test_a_move_file_dwells_likewise(tmp_path: Path) -> None:
    text = json.dumps({"moves": [{"dwell": 3600}] * 10_000})
    assert refusal(tmp_path, "dwells.json", text) == (
        f"move 38: the job's motion and dwells up to here last 38.0 h; {BOUND}")


def test_motion_and_dwells_are_counted_together(tmp_path: Path) -> None:
    """Moves at 1 mm/min (300 mm: 5 h) between dwells of an hour: 6 × 6 h + 5 h passes the bound at
    the 7th move (line 14)."""
    lines = ["G21 G90 F1"] + [f"G1 X{300 * ((k + 1) % 2)}\nG4 P3600" for k in range(10)]
    message = refusal(tmp_path, "mixed.gcode", "\n".join(lines) + "\n")
    assert message == ("line 14: the job's motion and dwells up to here last at least 41.0 h; "
                       + BOUND)


def test_the_least_ticks_of_a_move() -> None:
    assert move_ticks(10.0, 0.0, 0.0, 1.0, 0.1) == pytest.approx(20.0)  # a triangle: 2·√(L/a)
    assert move_ticks(10.0, 1.0, 1.0, 1.0, 0.1) == pytest.approx(10.0)  # straight through
    assert move_ticks(10.0, 0.0, 0.0, 0.5, 0.1) == pytest.approx(5.0 + 5.0 + (10.0 - 2.5) / 0.5)
    assert move_ticks(10.0, 0.0, 0.0, 1.0, 0.0) == float("inf")
