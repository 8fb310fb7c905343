"""The machine screen's job keys: open a job (planned whole, in the work coordinates), run it, go on
after a pause, hold and resume it (Space; the board's feed hold and cycle start buttons too). Alarms
and the buttons go to the log. Mixed into MachineScreen, whose log, session and worker threads they
use."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from textual.screen import Screen

from ..job import Job, is_move_file, load_job
from ..link import LinkError
from ..machine import JobProgress, JobRun, Machine, MachineError, MotionEnd
from ..machine.resume import job_journal, kept_job, resume_job
from ..mdi import Console
from ..planner.feed_override import MAX_PERCENT, MIN_PERCENT, STEP_PERCENT
from ..planner.program import JobError
from ..protocol import Alarm, InputCause, InputChange, Report
from ..toolpath import toolpath
from .console import ConsoleLine
from .job_dialog import JobDialog
from .messages import JobDone, JobStarted, Note
from .panels import JobPanel
from .preview import Preview, preview_lines
from .toolpath_view import ToolpathView

if TYPE_CHECKING:
    from ..jog import Jogger
    from .session import Session


def source_lines(path: Path) -> list[str]:
    """A G-code file's lines, to show the one running (a move file's entries have no line text)."""
    if is_move_file(path):
        return []
    try:
        return path.read_text(errors="replace").split("\n")
    except OSError:
        return []


class JobKeys(Screen[None]):
    """The part of MachineScreen that runs jobs."""

    session: Session
    job: JobRun | None
    job_name: str | None
    job_path: str
    job_source: list[str]
    console: Console | None
    preview: Preview | None = None  # a job planned and shown, waiting for Enter
    _pause_shown: int | None = None  # the line of the pause last announced

    if TYPE_CHECKING:  # MachineScreen's own

        def log_line(self, text: str, error: bool = False) -> None: ...
        def _jogger_ready(self, what: str) -> Jogger | None: ...
        def _thread(self, target: Callable[[], object], name: str) -> object: ...
        def _command(self, command: Callable[[], object], what: str) -> None: ...
        def show_keys(self) -> None: ...

    def action_open_job(self) -> None:
        if self._jogger_ready("job") is None:
            return
        self.app.push_screen(JobDialog(self.job_path), self._job_chosen)

    def _job_chosen(self, path: Path | None) -> None:
        """The file typed: read and planned whole (in a worker) and shown; Enter then runs it."""
        if path is None:
            return
        self.job_path = str(path)
        machine = self._machine_free("job")
        if machine is None:
            return
        self.preview = None
        self.log_line(f"planning {path}…")
        self.run_worker(lambda: self._plan_preview(machine, path), thread=True, group="preview")

    def _plan_preview(self, machine: Machine, path: Path) -> None:
        try:
            start = machine.sync()
            job = load_job(path, machine.config, start, coordinates=machine.coordinates)
            if len(job.plan) == 0:
                raise JobError(f"{job.path}: no move leaves the current position")
        except (JobError, LinkError, MachineError) as exc:
            self.post_message(Note(f"job not started: {exc}", error=True))
            return
        drawn = toolpath(job.program, machine.config.to_mm(start))
        preview = Preview(job, path, start, drawn, source_lines(path))
        self.app.call_from_thread(self._show_preview, preview, preview_lines(preview, machine))

    def _show_preview(self, preview: Preview, lines: list[str]) -> None:
        self.preview = preview
        view = self.query_one(ToolpathView)
        view.show_path(preview.toolpath)
        box = preview.toolpath.work_box
        if box is not None and len(box.low) > 1:  # the path view's foot: its size and time
            size = f"{box.high[0] - box.low[0]:.0f}×{box.high[1] - box.low[1]:.0f} mm"
            view.border_subtitle = f"{size} · {preview.job.plan.duration_s:.0f} s · Enter runs"
        for line in lines:
            self.log_line(line)
        seconds = preview.job.plan.duration_s
        self.query_one(JobPanel).show(
            None, None, f"{preview.path.name}: {seconds:.1f} s planned: Enter runs it, Esc drops it"
        )

    def action_run_preview(self) -> None:
        """Enter: the job shown runs (planned again if the machine moved since)."""
        preview, self.preview = self.preview, None
        if preview is None:
            return
        self.query_one(ToolpathView).border_subtitle = ""
        machine = self._machine_free("job")
        if machine is None or self._jogger_ready("job") is None:
            return
        path = preview.path

        def plan(start: tuple[int, ...]) -> Job:
            if start == preview.start and machine.coordinates == preview.job.coordinates:
                return preview.job
            return load_job(path, machine.config, start, coordinates=machine.coordinates)

        self._thread(
            lambda: self._job_worker(machine, path.name, plan, preview.source, path),
            "quadstep-job",
        )

    def drop_preview(self) -> bool:
        """Esc with a job shown: it is dropped (False: none was)."""
        if self.preview is None:
            return False
        self.preview = None
        self.query_one(ToolpathView).border_subtitle = ""
        self.query_one(JobPanel).show(None, None, "job dropped before it ran")
        self.log_line("job dropped: nothing moved")
        return True

    def offer_kept_job(self, machine: Machine) -> None:
        """On connect: a job that stopped before its end is named, with the key that goes on with
        it (its journal read in a thread of its own, off the event loop)."""

        def offer() -> None:
            try:
                kept = kept_job(machine)
            except MachineError as exc:
                self.post_message(Note(str(exc), error=True))
                return
            if kept is not None:
                self.post_message(
                    Note(
                        f"{Path(kept.job.path).name} stopped before its end ({kept.state}): "
                        "R resumes it from where motion stopped"
                    )
                )

        self._thread(offer, "quadstep-kept-job")

    def action_resume_kept(self) -> None:
        """R: the job kept in the machine's journal, planned from where the machine stands, run."""
        machine = self._machine_free("resume")
        if machine is None or self._jogger_ready("resume") is None:
            return

        def resume() -> None:
            try:
                kept = kept_job(machine)
            except MachineError as exc:
                self.post_message(Note(str(exc), error=True))
                return
            if kept is None:
                self.post_message(Note("resume: no stopped job is kept for this machine", True))
                return
            path = Path(kept.job.path)

            def plan(_start: tuple[int, ...]) -> Job:
                job, _, said = resume_job(machine, path)
                for line in said:
                    self.post_message(Note(line))
                return job

            self._job_worker(machine, path.name, plan, source_lines(path), path)

        self._thread(resume, "quadstep-job")

    def action_console(self) -> None:
        """`:` gives the keys to the console line (Esc gives them back)."""
        if self._jogger_ready("MDI") is not None:
            self.query_one(ConsoleLine).focus()

    def on_console_line_run(self, message: ConsoleLine.Run) -> None:
        """A line typed in the console: planned whole from where the machine stands, then run as a
        job."""
        text = message.text
        self.log_line(f"> {text}")
        machine = self._machine_free("MDI") if self._jogger_ready("MDI") is not None else None
        if machine is None:
            return
        if self.console is None or self.console.config is not machine.config:
            self.console = Console(machine.config)
        console = self.console

        def plan(start: tuple[int, ...]) -> Job:
            return console.plan(text, start, machine.coordinates)

        self._thread(
            lambda: self._job_worker(machine, "MDI", plan, [text], typed=True), "quadstep-mdi"
        )

    def action_macro(self, index: int) -> None:
        """A [[macros]] key: its lines planned whole from where the machine stands, in the
        console's modal state (as typed lines), then run."""
        macro = self.session.config.macros[index] if self.session.config is not None else None
        if macro is None:
            return
        self.log_line(f"macro {macro.name}: " + " | ".join(macro.gcode))
        what = f"macro {macro.name}"
        machine = self._machine_free(what) if self._jogger_ready(what) is not None else None
        if machine is None:
            return
        if self.console is None or self.console.config is not machine.config:
            self.console = Console(machine.config)
        console = self.console

        def plan(start: tuple[int, ...]) -> Job:
            return console.plan_lines(macro.gcode, start, machine.coordinates)

        self._thread(
            lambda: self._job_worker(machine, what, plan, list(macro.gcode), typed=True),
            "quadstep-macro",
        )

    def _machine_free(self, what: str) -> Machine | None:
        machine = self.session.machine
        if machine is None or machine.busy:
            self.log_line(f"{what}: the machine is busy", error=True)
            return None
        return machine

    def _job_worker(
        self,
        machine: Machine,
        name: str,
        plan: Callable[[tuple[int, ...]], Job],
        source: list[str],
        job_file: Path | None = None,
        typed: bool = False,
    ) -> None:
        """Plan and run a job (a file, or `typed` lines: the console's or a macro's) in this worker
        thread."""
        try:
            start = machine.sync()
            job = plan(start)
            if len(job.plan) == 0 and typed:
                machine.adopt_coordinates(job.end_coordinates)  # G10, G92, G54…G59: no motion
                system = machine.coordinates.name
                self.post_message(Note(f"{name}: done (no motion; {system} active)"))
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
            self.post_message(Note(f"{what} not started: {str(exc).removeprefix('MDI: ')}", True))
            return
        self.post_message(JobStarted(run, name, path, source))
        end = run.wait()
        assert end is not None
        self.post_message(JobDone(name, end))

    def on_job_started(self, message: JobStarted) -> None:
        job = message.job
        self.job = job
        self.job_name = message.name
        self.job_source = message.source
        if message.path is not None:
            self.query_one(ToolpathView).show_path(message.path)
        self.log_line(
            f"running {message.name}: {len(job.plan)} segments, {job.plan.duration_s:.1f} s planned"
        )
        self.show_keys()
        self.show_job(job.progress)

    def show_job(self, progress: JobProgress) -> None:
        """The job line: name, the line being run and its text, time left, progress; at a pause what
        it waits for (an M0, a tool change), said once in the log with what the operator may do."""
        line = progress.line
        text = self.job_source[line - 1] if 0 < line <= len(self.job_source) else ""
        pause = self.job.pause if self.job is not None else None
        reason = pause.reason if pause is not None else ""
        feed = self.job.feed_override if self.job is not None else 100
        self.query_one(JobPanel).show(self.job_name, progress, source=text, pause=reason, feed=feed)
        if pause is not None and self._pause_shown != pause.line:
            self._pause_shown = pause.line
            self.log_line(
                f"line {pause.line}: {reason}. Jog, zero (x y z 0), probe (p, t); g goes on"
            )
            jogger = self.session.jogger
            if jogger is not None:
                jogger.anchor()  # jogs plan from where the job stopped

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
        self.show_keys()
        self.query_one(JobPanel).show(None, None, f"{message.name}: {outcome}")
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self._command(jogger.sync, "sync")

    def action_hold_resume(self) -> bool:
        """Space while a job runs: a feed hold that keeps the rest of the job; again: resume. False:
        no job."""
        job = self.job
        if job is None:
            return False
        if job.held:
            job.resume()
            self.log_line("resuming: what is left is planned from here")
        else:
            self._thread(lambda: job.feed_hold(), "quadstep-feed-hold")
            self.log_line("feed hold: g goes on (Space too), Esc stops the job")
        return True

    def action_feed_override(self, delta: int) -> bool:
        """- + while a job runs: its feed override 10 % lower / higher (within 10–200 %); * (delta
        0) back to 100 %. It applies to what is not yet sent. False: no job."""
        job = self.job
        if job is None:
            return False
        percent = (
            100
            if delta == 0
            else min(MAX_PERCENT, max(MIN_PERCENT, job.feed_override + delta * STEP_PERCENT))
        )
        if percent == job.feed_override:
            if delta:
                self.log_line(
                    f"feed override: {percent} % is the {'most' if delta > 0 else 'least'}",
                    error=True,
                )
            return True
        try:
            job.set_feed_override(percent)
        except (ValueError, MachineError) as exc:
            self.log_line(f"feed override: {exc}", error=True)
            return True
        self.log_line(f"feed override {percent} %: from the first move not yet sent")
        self.show_job(job.progress)
        return True

    def watch_reports(self, machine: Machine) -> None:
        """Alarms (E_STOP, HARD_LIMIT, HOST_LOST) and the board's buttons, in the log."""

        def note(report: Report) -> None:
            if isinstance(report, Alarm):
                # the carriage's steps, as every other position shown (take-ups excluded)
                steps = machine.shown(report.position, report.motion_ticks)
                self.post_message(
                    Note(f"ALARM {report.code.name} at steps {list(steps)}; Ctrl+X clears it", True)
                )
            elif isinstance(report, InputChange) and report.cause in (
                InputCause.FEED_HOLD,
                InputCause.CYCLE_START,
            ):
                self.post_message(
                    Note(f"board button: {report.cause.name.lower().replace('_', ' ')}")
                )

        machine.on_report(note)

    def action_resume(self) -> None:
        job = self.job
        if job is None or job.paused_at is None:
            self.log_line("go on: no job waits at a pause", error=True)
        elif not job.resume():
            self.log_line("go on: wait until the machine is at rest", error=True)
        else:
            self._pause_shown = None
            self.log_line("going on")
