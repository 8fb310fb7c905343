"""A checked G-code file run as an open job (open_end.py), fed a part at a time while it runs: the
first part planned and started at once, each next one added (JobRun.extend) as the board's planned
motion runs short. Nothing holds the whole file: a part is read, handed over and dropped."""

from __future__ import annotations

import threading
from collections.abc import Iterator

from ..job_scan import GcodeParts, Part
from ..planner.feed_override import scale_feeds
from ..planner.plan import Plan, plan_program
from ..planner.program import JobError, Program
from .job import JobRun
from .machine import Machine

# A part is added once the job has less than this much planned motion the board has not run, and
# fewer segments than this (short lines), and has planned what it was given before.
AHEAD_S = 2.5
AHEAD_SEGMENTS = 2000
POLL_S = 0.02  # s between looks at how far the job is ahead


class FileFeed:
    """The job of a file and the thread that feeds it the file's parts; `error` says why the feed
    stopped short of the file's end (the job is halted then), None otherwise."""

    def __init__(self, run: JobRun, parts: Iterator[Part], label: str) -> None:
        self.run = run
        self.error: str | None = None
        self._parts = parts
        self._label = label
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._feed, name="quadstep-feed", daemon=True)

    def start(self) -> FileFeed:
        self._thread.start()
        return self

    def stop(self) -> None:
        """Feed no more (the job was stopped) and wait for the feeding thread."""
        self._stop.set()
        self._thread.join()

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
                if self._stop.is_set() or self.run.end is not None:
                    return
                if part.items and not self.run.extend(part.items, part.lines, part.coordinates):
                    if self.run.open or self.run.end is None or self.run.end.ended_by != "done":
                        return  # stopped meanwhile
                    self.error = (
                        f"the machine ran everything planned before {self._label} "
                        f"{part.items[0].line} was planned (the computer fell behind): stopped "
                        "there at rest"
                    )
                    return
        except JobError as exc:  # the file changed since it was checked
            self.error = str(exc)
            self.run.halt("error")
        finally:
            self.run.close()


def first_plan(
    parts: Iterator[Part], machine: Machine, feed_override: int, label: str
) -> tuple[Plan, Program]:
    """The first parts of the file, as many as make a move, planned from where the machine
    stands."""
    program = Program()
    for part in parts:
        program.items.extend(part.items)
        program.lines, program.coordinates = part.lines, part.coordinates
        plan = plan_program(
            scale_feeds(program, feed_override), machine.config, machine.position, label
        )
        if len(plan):
            return plan, program
    return plan_program(program, machine.config, machine.position, label), program


def feed_file(
    machine: Machine, reader: GcodeParts, feed_override: int = 100, label: str = "line"
) -> FileFeed:
    """Start the file `reader` reads on `machine` (checked before: scan_job) and feed it the rest
    while it runs."""
    parts = reader.parts()
    plan, program = first_plan(parts, machine, feed_override, label)
    run = machine.run_job(plan, program, label, feed_override, None, open_end=True)
    return FileFeed(run, parts, label).start()
