"""What a long open job ran, across the plans it let go of (machine/rebase.py), and how it is given
its lines: shared by the rolling-leg tests of quadratic and jerk-limited jobs."""

from __future__ import annotations

from dataclasses import replace

import pytest
from waiting import wait_until

from quadstep.config import MachineConfig
from quadstep.link import Link
from quadstep.machine import JobRun, JobState, Machine
from quadstep.machine import job as job_module
from quadstep.planner.plan import plan_program
from quadstep.planner.program import Program


ROW_MOVES = 20


def rows(count: int) -> str:
    """Rows of 0.5 mm moves along X, back and forth (X reverses at each row's end), 1 mm apart in
    Y."""
    out, x = ["G21 G90 F2400"], 0.0
    for row in range(count):
        step = 0.5 if row % 2 == 0 else -0.5
        for _ in range(ROW_MOVES):
            x += step
            out.append(f"G1 X{x:.3f}")
        out.append(f"G1 Y{row + 1}")
    return "\n".join(out) + "\n"


class WhatRan:
    """The segments the board ran, in order: what each plan let go of, each leg run to its end (on a
    busy computer the job goes on from rest) and what a leg that ran dry ran; `rebases`: how many
    times it let go."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        # (stream, first, end): read once the job ran, as building thousands of segments in the
        # job's thread would hold it back while the board runs
        self.parts: list = []
        self.rebases = 0
        let_go, next_leg = job_module.rebased, JobRun._next_leg

        def recorded(plan, at):  # noqa: ANN001, ANN202
            self.rebases += 1
            self.parts.append((plan.segments, 0, at.index))
            return let_go(plan, at)

        def leg_ran(run: JobRun, here: tuple[int, ...]):  # noqa: ANN202
            before = run.states.history[-2:]
            if before == [JobState.STREAMING, JobState.RESUMING]:  # after a done: all of it
                self.parts.append((run.plan.segments, 0, len(run.plan.segments)))
            elif before == [JobState.STARVED, JobState.RESUMING]:  # the board ran dry: what it ran
                ran = run.progress.done - sum(end - first for _, first, end in self.parts)
                self.parts.append((run.plan.segments, 0, ran))
            return next_leg(run, here)

        monkeypatch.setattr(job_module, "rebased", recorded)
        monkeypatch.setattr(JobRun, "_next_leg", leg_ran)

    @property
    def sent(self) -> list:
        return [segment for stream, first, end in self.parts for segment in stream.segments(first, end)]



def give_in_parts(run: JobRun, whole: Program, head: int, part: int, ahead: int) -> int:
    """The items of `whole` after its first `head` given to `run` `part` at a time, each once the
    machine is within `ahead` lines of what it was given; closed after; returns the longest plan
    the job kept meanwhile."""
    longest = 0
    for given in range(head, len(whole.items), part):
        wait_until(lambda: run.progress.line >= given - ahead)
        longest = max(longest, len(run.plan))
        items = whole.items[given : given + part]
        assert run.extend(items, items[-1].line)
    run.close()
    return longest


def run_in_parts(
    url: str, config: MachineConfig, whole: Program, head: int, part: int, ahead: int
) -> tuple[JobRun, int]:
    """`whole` run as an open job on the board at `url`: its first `head` items planned, the rest
    given as give_in_parts() gives them; it ends done on the whole program's last target. Returns
    the job and the longest plan it kept."""
    with Link.open(url) as link:
        machine = Machine(link, config)
        program = replace(whole, items=whole.items[:head])
        run = machine.run_job(plan_program(program, config, (0, 0, 0)), program, open_end=True)
        longest = give_in_parts(run, whole, head, part, ahead)
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == plan_program(whole, config, (0, 0, 0)).end
    return run, longest
