"""A checked G-code file run as an open job (open_end.py), fed a part at a time while it runs: the
first part planned and started at once, each next one added (JobRun.extend) as the board's planned
motion runs short. Nothing holds the whole file: a part is read, handed over and dropped."""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from itertools import chain

from ..job_scan import GcodeParts, Part
from ..planner.feed_override import scale_feeds
from ..planner.plan import Plan, plan_program
from ..planner.program import JobError, Program
from .errors import MachineError
from .job import JobRun
from .machine import Machine

# A part is added once the job has less than this much planned motion the board has not run, and
# fewer segments than this (short lines), and has planned what it was given before.
AHEAD_S = 2.5
AHEAD_SEGMENTS = 2000
# The first job of a file starts with this many parts planned: enough motion ahead of it to plan
# the next parts while it runs (a few tenths of a second to plan).
FIRST_PARTS = 4
POLL_S = 0.02  # s between looks at how far the job is ahead


class FileFeed:
    """The running job of a file and the thread that feeds it the file's parts. Where the machine
    ran everything planned before the next part was (a busy computer, a board that runs faster than
    real time) the job ended at rest there: the next job goes on from there with the next part
    (`run` is the one under way; next_run() waits for it). `error` says why the feed stopped short
    of the file's end (the job halted then), None otherwise."""

    def __init__(
        self,
        machine: Machine,
        run: JobRun,
        parts: Iterator[Part],
        feed_override: int,
        label: str,
        on_run: Callable[[JobRun], None] | None = None,
    ) -> None:
        self.machine = machine
        self.run = run
        self.error: str | None = None
        self.segments_before = 0  # segments of the jobs before the one under way
        self._parts = parts
        self._feed_override = feed_override
        self._label = label
        self._on_run = on_run
        self._stop = threading.Event()
        self._changed = threading.Condition()
        self._done = False
        self._thread = threading.Thread(target=self._feed, name="quadstep-feed", daemon=True)
        if on_run is not None:
            on_run(run)

    def start(self) -> FileFeed:
        self._thread.start()
        return self

    def stop(self) -> None:
        """Feed no more (the job was stopped) and wait for the feeding thread."""
        self._stop.set()
        self._thread.join()

    def next_run(self, ended: JobRun) -> JobRun | None:
        """After `ended` ended at the end of what it was given: the job that goes on with the rest
        of the file, or None when there is none."""
        with self._changed:
            self._changed.wait_for(lambda: self.run is not ended or self._done)
            return self.run if self.run is not ended else None

    def _ahead(self) -> bool:
        """The job has enough to run for now."""
        run = self.run
        if run.pending:
            return True
        now = run.progress
        return now.seconds_left >= AHEAD_S or now.total - now.done >= AHEAD_SEGMENTS

    def _feed(self) -> None:
        try:
            for part in self._parts:
                while self.run.end is None and self._ahead() and not self._stop.is_set():
                    self._stop.wait(POLL_S)
                if self._stop.is_set():
                    return
                if self.run.end is None and (
                    not part.items or self.run.extend(part.items, part.lines, part.coordinates)
                ):
                    continue
                if self.run.wait() is None or self.run.end is None:
                    return
                if self.run.end.ended_by != "done":
                    return  # stopped, or failed: the job says why
                self._go_on(part)
        except (JobError, MachineError) as exc:  # the file changed since it was checked
            self.error = str(exc)
            self.run.halt("error")
        finally:
            self.run.close()
            with self._changed:
                self._done = True
                self._changed.notify_all()

    def _go_on(self, part: Part) -> None:
        """The job ran everything it was given and ended at rest: the next from there, with
        `part`."""
        now = self.run.progress
        plan, program = first_plan(
            chain([part], self._parts), self.machine, self._feed_override, self._label
        )
        run = self.machine.run_job(
            plan, program, self._label, self._feed_override, None, open_end=True
        )
        if self._on_run is not None:
            self._on_run(run)
        with self._changed:
            self.segments_before += now.total
            self.run = run
            self._changed.notify_all()


def first_plan(
    parts: Iterator[Part], machine: Machine, feed_override: int, label: str
) -> tuple[Plan, Program]:
    """The first FIRST_PARTS parts of the file, or as many more as make a move, planned from where
    the machine stands: the job starts with that much ahead of it while the next parts are
    planned."""
    program = Program()
    for taken, part in enumerate(parts, start=1):
        program.items.extend(part.items)
        program.lines, program.coordinates = part.lines, part.coordinates
        if taken < FIRST_PARTS:
            continue
        plan = plan_program(
            scale_feeds(program, feed_override), machine.config, machine.position, label
        )
        if len(plan):
            return plan, program
    return plan_program(
        scale_feeds(program, feed_override), machine.config, machine.position, label
    ), program


def feed_file(
    machine: Machine,
    reader: GcodeParts,
    feed_override: int = 100,
    label: str = "line",
    on_run: Callable[[JobRun], None] | None = None,
) -> FileFeed:
    """Start the file `reader` reads on `machine` (checked before: scan_job) and feed it the rest
    while it runs; `on_run` is told of each job it starts."""
    parts = reader.parts()
    plan, program = first_plan(parts, machine, feed_override, label)
    run = machine.run_job(plan, program, label, feed_override, None, open_end=True)
    return FileFeed(machine, run, parts, feed_override, label, on_run).start()
