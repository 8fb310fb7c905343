"""The machine screen's job keys: open a job (planned whole, in the work coordinates), run it, go on
after a pause, hold and resume it (Space; the board's feed hold and cycle start buttons too). Alarms and
the buttons go to the log. Mixed into MachineScreen, whose log, session and worker threads they use."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from textual.screen import Screen

from ..job import Job, load_job
from ..link import LinkError
from ..machine import JobRun, Machine, MachineError, MotionEnd
from ..planner.program import JobError
from ..protocol import Alarm, InputCause, InputChange, Report
from .job_dialog import JobDialog
from .messages import JobDone, JobStarted, Note
from .panels import JobPanel

if TYPE_CHECKING:
    from .session import Session


class JobKeys(Screen[None]):
    """The part of MachineScreen that runs jobs."""

    session: Session
    job: JobRun | None
    job_name: str | None
    job_path: str

    if TYPE_CHECKING:  # MachineScreen's own
        def log_line(self, text: str, error: bool = False) -> None: ...
        def _jogger_ready(self, what: str) -> object: ...
        def _thread(self, target: Callable[[], object], name: str) -> object: ...
        def _command(self, command: Callable[[], object], what: str) -> None: ...

    def action_open_job(self) -> None:
        if self._jogger_ready("job") is None:
            return
        self.app.push_screen(JobDialog(self.job_path), self._job_chosen)

    def _job_chosen(self, path: Path | None) -> None:
        if path is None:
            return
        self.job_path = str(path)
        machine = self.session.machine
        if machine is None or machine.busy:
            self.log_line("job: the machine is busy", error=True)
            return
        self.log_line(f"planning {path}…")
        self._thread(lambda: self._job_worker(machine, path), "quadstep-job")

    def _job_worker(self, machine: Machine, path: Path) -> None:
        try:
            job: Job = load_job(path, machine.config, machine.sync(), coordinates=machine.coordinates)
            if len(job.plan) == 0:
                raise JobError(f"{path}: no move leaves the current position")
            run = machine.run_job(job.plan, job.program, job.label)
        except (JobError, LinkError, MachineError) as exc:
            self.post_message(Note(f"job not started: {exc}", error=True))
            return
        self.post_message(JobStarted(run, path.name))
        end = run.wait()
        assert end is not None
        if end.ended_by == "done":
            machine.adopt_coordinates(job.end_coordinates)  # what its G10, G92, G54…G59, M2/M30 left
        self.post_message(JobDone(path.name, end))

    def on_job_started(self, message: JobStarted) -> None:
        job = message.job
        self.job = job
        self.job_name = message.name
        self.log_line(f"running {message.name}: {len(job.plan)} segments, {job.plan.duration_s:.1f} s planned")
        self.query_one(JobPanel).show(self.job_name, job.progress)

    def on_job_done(self, message: JobDone) -> None:
        job = self.job
        self.job = None
        end: MotionEnd = message.end
        if end.ended_by == "done":
            outcome = "done"
        elif end.error:
            outcome = f"failed: {end.error}"
        else:
            line = job.progress.line if job is not None else "?"
            outcome = f"stopped near line {line} ({'HOLD' if end.held else 'STOP'})"
        self.log_line(f"{message.name}: {outcome}", error=bool(end.error))
        self.query_one(JobPanel).show(None, None, f"{message.name}: {outcome}")
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self._command(jogger.sync, "sync")

    def action_hold_resume(self) -> bool:
        """Space while a job runs: a feed hold that keeps the rest of the job; again: resume. False: no job."""
        job = self.job
        if job is None:
            return False
        if job.held:
            job.resume()
            self.log_line("resuming: what is left is planned from here")
        else:
            self._thread(lambda: job.feed_hold(), "quadstep-feed-hold")
            self.log_line("feed hold: Space resumes, Esc stops the job")
        return True

    def watch_reports(self, machine: Machine) -> None:
        """Alarms (E_STOP, HARD_LIMIT, UNDERRUN, HOST_LOST) and the board's buttons, in the log."""
        def note(report: Report) -> None:
            if isinstance(report, Alarm):
                self.post_message(Note(f"ALARM {report.code.name} at steps {list(report.position)}; "
                                       "Ctrl+X clears it", error=True))
            elif isinstance(report, InputChange) and report.cause in (InputCause.FEED_HOLD, InputCause.CYCLE_START):
                self.post_message(Note(f"board button: {report.cause.name.lower().replace('_', ' ')}"))
        machine.on_report(note)

    def action_resume(self) -> None:
        if self.job is None or not self.job.resume():
            self.log_line("go on: no job waits at a pause", error=True)
