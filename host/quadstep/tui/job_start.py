"""The machine screen's jobs, on the worker side: a file planned whole for the preview, a job (a
file, a console line, a macro) planned and run, the job a crash left behind offered and resumed,
alarms and the board's buttons. Each runs in a worker thread and tells the screen what happened only
with messages (messages.py): it reads and changes no widget and no screen state."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..job import Job, is_move_file, load_job
from ..link import LinkError
from ..machine import Machine, MachineError
from ..machine.resume import job_journal, kept_job, resume_job
from ..planner.program import JobError
from ..protocol import Alarm, InputCause, InputChange, Report
from ..toolpath import toolpath
from .commands import Post
from .messages import JobDone, JobStarted, Note, PreviewReady
from .preview import Preview, preview_lines

Plan = Callable[[tuple[int, ...]], Job]  # a job planned from the machine's position (steps)


def source_lines(path: Path) -> list[str]:
    """A G-code file's lines, to show the one running (a move file's entries have no line text)."""
    if is_move_file(path):
        return []
    try:
        return path.read_text(errors="replace").split("\n")
    except OSError:
        return []


class JobStarter:
    def __init__(self, post: Post) -> None:
        self.post = post

    def plan_preview(self, machine: Machine, path: Path) -> None:
        """A file read and planned whole from where the machine stands, to be shown."""
        try:
            start = machine.sync()
            job = load_job(path, machine.config, start, coordinates=machine.coordinates)
            if len(job.plan) == 0:
                raise JobError(f"{job.path}: no move leaves the current position")
        except (JobError, LinkError, MachineError) as exc:
            self.post(Note(f"job not started: {exc}", error=True))
            return
        drawn = toolpath(job.program, machine.config.to_mm(start))
        preview = Preview(job, path, start, drawn, source_lines(path))
        self.post(PreviewReady(preview, preview_lines(preview, machine)))

    def run(
        self,
        machine: Machine,
        name: str,
        plan: Plan,
        source: list[str],
        job_file: Path | None = None,
        typed: bool = False,
    ) -> None:
        """Plan and run a job (a file, or `typed` lines: the console's or a macro's) to its end."""
        try:
            start = machine.sync()
            job = plan(start)
            if len(job.plan) == 0 and typed:
                machine.adopt_coordinates(job.end_coordinates)  # G10, G92, G54…G59: no motion
                system = machine.coordinates.name
                self.post(Note(f"{name}: done (no motion; {system} active)"))
                return
            if len(job.plan) == 0:
                raise JobError(f"{job.path}: no move leaves the current position")
            path = toolpath(job.program, machine.config.to_mm(start)) if not typed else None
            journal = job_journal(machine, job_file) if job_file is not None else None
            run = machine.run_job(
                job.plan, job.program, job.label, journal=journal, leaves=job.end_coordinates
            )
        except (JobError, LinkError, MachineError) as exc:
            what = name if typed else "job"
            self.post(Note(f"{what} not started: {str(exc).removeprefix('MDI: ')}", True))
            return
        self.post(JobStarted(run, name, path, source))
        end = run.wait()
        assert end is not None
        self.post(JobDone(name, end))

    def offer_kept(self, machine: Machine) -> None:
        """On connect: a job that stopped before its end is named, with the key that goes on."""
        try:
            kept = kept_job(machine)
        except MachineError as exc:
            self.post(Note(str(exc), error=True))
            return
        if kept is not None:
            name = Path(kept.job.path).name
            said = f"{name} stopped before its end ({kept.state})"
            self.post(Note(f"{said}: R resumes it from where motion stopped"))

    def resume_kept(self, machine: Machine) -> None:
        """The job kept in the machine's journal, planned from where the machine stands, run."""
        try:
            kept = kept_job(machine)
        except MachineError as exc:
            self.post(Note(str(exc), error=True))
            return
        if kept is None:
            self.post(Note("resume: no stopped job is kept for this machine", True))
            return
        path = Path(kept.job.path)

        def plan(_start: tuple[int, ...]) -> Job:
            job, _, said = resume_job(machine, path)
            for line in said:
                self.post(Note(line))
            return job

        self.run(machine, path.name, plan, source_lines(path), path)

    def watch_reports(self, machine: Machine) -> None:
        """Alarms (E_STOP, HARD_LIMIT, HOST_LOST) and the board's buttons, in the log."""

        def note(report: Report) -> None:
            if isinstance(report, Alarm):
                # the carriage's steps, as every other position shown (take-ups excluded)
                steps = machine.standing.shown(report.position, report.motion_ticks)
                self.post(
                    Note(f"ALARM {report.code.name} at steps {list(steps)}; Ctrl+X clears it", True)
                )
            elif isinstance(report, InputChange) and report.cause in (
                InputCause.FEED_HOLD,
                InputCause.CYCLE_START,
            ):
                self.post(Note(f"board button: {report.cause.name.lower().replace('_', ' ')}"))

        machine.on_report(note)
