"""Move files (JSON or YAML): the schema, units, and errors that name the move and field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from quadstep.movefile import move_program, read_move_file
from quadstep.planner.program import Dwell, JobError, LinearMove, Pause

REPO = Path(__file__).resolve().parents[2]
XYZ = ("X", "Y", "Z")


def write(tmp_path: Path, data: object, name: str = "job.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def test_example_move_file_reads() -> None:
    moves = read_move_file(REPO / "examples" / "moves.yaml")
    program = move_program(moves, XYZ, (0.0, 0.0, 0.0))
    assert program.lines == len(moves.moves)
    assert any(isinstance(item, Dwell) for item in program.items)


def test_absolute_relative_rapid_dwell_pause_and_units(tmp_path: Path) -> None:
    path = write(tmp_path, {
        "feed_unit": "mm/min",
        "moves": [
            {"to": {"X": 10, "Y": 5}, "feed": 600},
            {"by": {"Z": -1}, "feed": 120, "accel": 50},
            {"rapid_by": {"X": 1}},
            {"rapid_to": {"Y": 0}},
            {"dwell": 0.5},
            {"pause": True},
        ],
    })
    program = move_program(read_move_file(path), XYZ, (1.0, 2.0, 3.0))
    assert program.items == [
        LinearMove(1, (10.0, 5.0, 3.0), 10.0),
        LinearMove(2, (10.0, 5.0, 2.0), 2.0, 50.0),
        LinearMove(3, (11.0, 5.0, 2.0), None),
        LinearMove(4, (11.0, 0.0, 2.0), None),
        Dwell(5, 0.5),
        Pause(6),
    ]


def test_yaml_and_feeds_in_mm_per_second(tmp_path: Path) -> None:
    path = tmp_path / "job.yaml"
    path.write_text("moves:\n  - to: {X: 3}\n    feed: 7\n")
    program = move_program(read_move_file(path), XYZ, (0.0, 0.0, 0.0))
    assert program.items == [LinearMove(1, (3.0, 0.0, 0.0), 7.0)]


@pytest.mark.parametrize(
    ("moves", "message"),
    [
        ([{"to": {"X": 1}}], "moves[0]: 'to' needs a feed"),
        ([{"to": {"X": 1}, "feed": 5}, {"to": {"X": 1}, "by": {"X": 1}, "feed": 5}],
         "moves[1]: needs exactly one of to, by, rapid_to, rapid_by, dwell, pause (got ['to', 'by'])"),
        ([{"feed": 5}], "moves[0]: needs exactly one of to, by, rapid_to, rapid_by, dwell, pause (got none)"),
        ([{"rapid_to": {"X": 1}, "feed": 5}], "moves[0]: feed applies only to 'to' and 'by' moves, not 'rapid_to'"),
        ([{"dwell": 1, "accel": 5}], "moves[0]: accel applies only to moves, not 'dwell'"),
        ([{"to": {"X": 1}, "feed": -2}], "moves[0].feed = -2: must be greater than 0"),
        ([{"dwell": -1}], "moves[0].dwell = -1: must be at least 0"),
        ([{"to": {"B": 1}, "feed": 1}], "moves[0].to.B = 'B': must be one of 'X', 'Y', 'Z' or 'A'"),
        ([{"go": {"X": 1}}], "moves[0].go: unknown key"),
        ([], "moves = []: needs at least 1 entry"),
    ],
)
def test_bad_moves_name_the_move_and_field(tmp_path: Path, moves: list[object], message: str) -> None:
    path = write(tmp_path, {"moves": moves})
    with pytest.raises(JobError) as caught:
        read_move_file(path)
    assert str(caught.value).splitlines()[0] == f"{path}: {message}"


def test_axis_missing_from_the_machine(tmp_path: Path) -> None:
    path = write(tmp_path, {"moves": [{"to": {"X": 1}, "feed": 1}, {"to": {"A": 1}, "feed": 1}]})
    with pytest.raises(JobError, match=r"^move 2: axis A is not on this machine \(axes X, Y, Z\)$"):
        move_program(read_move_file(path), XYZ, (0.0, 0.0, 0.0))


def test_not_json(tmp_path: Path) -> None:
    path = tmp_path / "job.json"
    path.write_text("{moves: [")
    with pytest.raises(JobError, match=r"job\.json: not valid JSON"):
        read_move_file(path)


def test_not_text(tmp_path: Path) -> None:
    path = tmp_path / "job.json"
    path.write_bytes(b'{"moves": [\xff]}')
    with pytest.raises(JobError, match=r"^.*job\.json: not a text file \(invalid start byte at byte 11\)$"):
        read_move_file(path)
