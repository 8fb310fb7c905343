"""The job's journal (machine/journal.py), without a port: a leg kept and read back means the same program, and
the board's count of segments names the move to go on from."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.machine.job_legs import stream_move_ends
from quadstep.machine.journal import (
    Journal, JournalError, JobIdentity, file_digest, item_of, journal_path, read_journal, record_of,
    rest_to_resume, resume_item,
)
from quadstep.planner.program import LinearMove, Pause, SetOutputs

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
JOB = """G21 G90
G0 X5 Y5
M3 S10000
G1 X20 F600
G2 X30 Y15 I10 J0
M0
G1 Y25 Z-1
G1 X0 Y0 Z0
M5
"""


def kept(tmp_path: Path, text: str = JOB):
    path = tmp_path / "job.gcode"
    path.write_text(text)
    job = load_job(path, CONFIG)
    journal = Journal(journal_path(tmp_path / "state.json"), JobIdentity(
        path=str(path.resolve()), sha256=file_digest(path), label="line"), boot_id=7)
    journal.begin_leg(job.program, job.plan.start, stream_move_ends(job.plan), len(job.plan), 2**32 - 3, 100)
    read = read_journal(journal.path)
    assert read is not None
    return job, journal, read


def test_every_item_reads_back_as_itself(tmp_path: Path) -> None:
    job, _, read = kept(tmp_path)
    assert [item_of(r) for r in read.leg.items] == job.program.items
    assert all(item_of(record_of(i)) == i for i in job.program.items)
    assert read.boot_id == 7 and read.leg.board_done == 2**32 - 3  # the board's counter, as it wraps


def test_the_board_count_names_the_move_under_way(tmp_path: Path) -> None:
    job, _, read = kept(tmp_path)
    base = 2**32 - 3
    program = job.program
    moves = [i for i, item in enumerate(program.items) if isinstance(item, LinearMove)]
    assert resume_item(read, program, CONFIG, base) == moves[0]  # nothing done: the first move
    ends = stream_move_ends(job.plan)
    for move, end in enumerate(ends[:-1]):
        # the last segment of a move running: that move again; its end reached: the next one
        assert resume_item(read, program, CONFIG, (base + end - 1) % 2**32) == moves[move]
        assert resume_item(read, program, CONFIG, (base + end) % 2**32) == moves[move + 1]
    assert resume_item(read, program, CONFIG, (base + ends[-1]) % 2**32) == len(program.items)
    with pytest.raises(JournalError, match="reset"):
        resume_item(read, program, CONFIG, base + len(job.plan) + 1)


def test_the_rest_keeps_the_outputs_and_waits_again_at_the_pause(tmp_path: Path) -> None:
    job, journal, read = kept(tmp_path)
    ends = stream_move_ends(job.plan)
    at = CONFIG.to_steps((20.0, 5.0, 0.0))  # stopped at the end of the G1 X20, in the arc's first piece
    rest, approach = rest_to_resume(read, job.program, CONFIG, (2**32 - 3 + ends[1] + 1) % 2**32, at)
    assert approach is None
    assert isinstance(rest.items[0], SetOutputs) and rest.items[0].state.spindle == 3  # M3 again first
    assert rest.items[1:] == job.program.items[job.program.items.index(rest.items[1]):]
    journal.state("paused", 6)
    read = read_journal(journal.path)
    assert read is not None and read.waiting_at == 6
    rest, _ = rest_to_resume(read, job.program, CONFIG, 0, at)
    assert isinstance(rest.items[1], Pause) and rest.items[1].line == 6


def test_a_machine_moved_since_the_stop_is_refused_unless_homed_then_approached(tmp_path: Path) -> None:
    job, _, read = kept(tmp_path)
    ends = stream_move_ends(job.plan)
    home = CONFIG.to_steps((200.0, 5.0, 0.0))
    done = (2**32 - 3 + ends[2] + 1) % 2**32  # in the arc's second chord
    with pytest.raises(JournalError, match="moved since the job stopped"):
        rest_to_resume(read, job.program, CONFIG, done, home)
    rest, approach = rest_to_resume(read, job.program, CONFIG, done, home, homed=True)
    assert approach is not None and approach.startswith("starting at line 5: ")
    item = resume_item(read, job.program, CONFIG, done)
    moves = [i for i in job.program.items if isinstance(i, LinearMove)]
    interrupted = moves.index(job.program.items[item])
    assert interrupted == 3  # the arc's second chord: ends[2] passed
    assert rest.items[-(len(job.program.items) - item):] == job.program.items[item:]  # as written after
    over = [i for i in rest.items[:len(rest.items) - (len(job.program.items) - item)] if isinstance(i, LinearMove)]
    assert CONFIG.to_steps(over[-1].target) == CONFIG.to_steps(moves[2].target)  # down onto the chord's start


def test_a_done_job_leaves_no_journal(tmp_path: Path) -> None:
    _, journal, _ = kept(tmp_path)
    journal.finish()
    assert read_journal(journal.path) is None
