"""The whole-file check in one pass (job_scan.py) finds what reading and planning the file whole finds:
the same totals, the same first error (a syntax error anywhere before a target outside the travel before
the duration limit), a part at a time."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.job_scan import GcodeParts, job_lines, scan_job
from quadstep.planner.program import JobError

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
START = (400, 800, 0)


def whole(path: Path, skip: bool = False) -> tuple[object, ...] | str:
    try:
        job = load_job(path, CONFIG, START, skip)
    except JobError as exc:
        return str(exc)
    return (
        job.plan.moves,
        job.program.lines,
        job.plan.end,
        job.program.end_line,
        job.program.after_end,
    )


def scanned(path: Path, skip: bool = False) -> tuple[object, ...] | str:
    try:
        scan = scan_job(path, CONFIG, START, skip)
    except JobError as exc:
        return str(exc)
    return scan.moves, scan.lines, scan.end_steps, scan.end_line, scan.after_end


ARCS = "G21 G90 F900\n" + "".join(
    f"G1 X{10 + k % 7} Y{5 + k % 3}\nG2 X{12 + k % 7} Y{5 + k % 3} I1 J0\n" for k in range(400)
)
CASES = {
    "arcs": ARCS,
    "offsets": "G10 L2 P2 X20 Y30\nG55 G1 X1 Y1 F600\nG91 G1 X2\nG90 G92 X0\nG1 X5\nG92.1\nG53 G0 X0 Y0\n"
    * 120,
    "ended": ARCS + "M2\nG1 X3\n(note)\nG1 Y4\n",
    "travel": ARCS + "G1 Y250\n" + ARCS,
    "syntax after travel": ARCS + "G1 Y250\n" + ARCS + "G1 X3O\n",
    "duration": "G1 X10 F0.0000000001\n" + ARCS,
    "travel after duration": "G1 X10 F0.0000000001\n" + ARCS + "G1 X-5\n",
    "no final newline": "G1 X1 F600\r\nG1 X2\r\nG1 X3",
}


@pytest.mark.parametrize("name", CASES)
def test_the_scan_finds_what_the_whole_plan_finds(name: str, tmp_path: Path) -> None:
    path = tmp_path / f"{name.replace(' ', '_')}.gcode"
    path.write_text(CASES[name], newline="")
    expected = whole(path)
    assert scanned(path) == expected
    if name in ("travel", "syntax after travel", "duration", "travel after duration"):
        assert isinstance(expected, str)  # an error, each of its kind
    else:
        assert not isinstance(expected, str), expected


def test_parts_hold_the_items_of_their_lines(tmp_path: Path) -> None:
    path = tmp_path / "arcs.gcode"
    path.write_text(ARCS)
    reader = GcodeParts(path, CONFIG, START, chunk_lines=100)
    parts = list(reader.parts())
    assert [part.lines for part in parts] == [100 * k for k in range(1, 9)] + [801]
    items = [item for part in parts for item in part.items]
    assert items == load_job(path, CONFIG, START).program.items


def test_skipped_words_are_counted_beyond_those_kept(tmp_path: Path) -> None:
    path = tmp_path / "spindle.gcode"
    path.write_text("G1 X1 F600\n" + "S1000 G1 X2\nS2000 G1 X3\n" * 100)
    scan = scan_job(path, CONFIG, START, skip_unsupported=True)
    assert scan.skipped_count == 200 and len(scan.skipped) == 100
    assert scan.skipped[:2] == [(2, "S1000"), (3, "S2000")]


def test_a_file_that_is_not_text_is_refused_at_its_byte(tmp_path: Path) -> None:
    path = tmp_path / "bin.gcode"
    path.write_bytes(b"G1 X1 F600\nG1 X2\xff\n")
    with pytest.raises(JobError) as error:
        list(job_lines(path))
    assert str(error.value) == f"{path}: not a text file (invalid start byte at byte 16)"
    assert whole(path) == str(error.value)
