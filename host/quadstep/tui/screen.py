"""The machine screen: what the machine does, and the keys that jog it, zero it, home and probe it,
run jobs and set the overrides. Its bindings (keys.py) are its actions here.

Nothing here waits on the serial line: connecting, polling, jogging and jobs run off the event loop
(commands.py, job_start.py) and report back with messages (messages.py), which the handlers here
show.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.reactive import reactive
from textual.screen import Screen
from textual.widgets import Header, Static

from ..job import Job, load_job
from ..jog import Jogger, JogMode, JogResult
from ..jog.step_queue import QueuedStep
from ..link import LinkError
from ..machine import JobProgress, JobRun, Machine, MachineError, MotionEnd
from ..machine.homing import home
from ..machine.probing import probe
from ..mdi import Console
from ..planner.feed_override import STEP_PERCENT, clamped
from ..protocol import AXIS_NAMES, Board
from .backlash_screen import BacklashScreen
from .commands import Commands
from .console import ConsoleLine
from .help import HelpScreen
from .job_dialog import JobDialog
from .job_start import JobStarter, Plan
from .keys import CONSOLE_KEY_LINE, JOB_KEY_LINE, JOG_KEYS, KEY_LINE, bindings
from .messages import (
    Connected,
    ConnectionLost,
    JobDone,
    JobStarted,
    JogDone,
    Note,
    PreviewReady,
    StatusUpdate,
)
from .panels import JobPanel, JogPanel, MachinePanel, MessageLog, PositionPanel
from .preview import Preview
from .session import Session, Snapshot
from .toolpath_view import ToolpathView
from .touch_off_screen import TouchOffScreen

POLL_INTERVAL = 0.1  # s between STATUS requests

# what may run while a job waits at its pause (M0, M6)
AT_A_PAUSE = ("jog", "zero", "G38.2", "G38.4", "touch-off")

NEXT_RAPID = {100: 50, 50: 25, 25: 100}  # r: full, half, a quarter, full again


def _board_name(board: int) -> str:
    try:
        return Board(board).name.lower()
    except ValueError:
        return f"board {board}"


class MachineScreen(Screen[None]):
    BINDINGS = bindings(9)  # step keys beyond the presets are hidden by check_action
    AUTO_FOCUS = ""  # nothing: every key jogs until `:` focuses the console line
    console_has_keys: reactive[bool] = reactive(False)  # the key line and the jog line say so

    def __init__(
        self, session: Session, job_path: str = "", poll_interval: float = POLL_INTERVAL
    ) -> None:
        super().__init__()
        self.session = session
        session.on_jog = self.jog_finished
        self.commands = Commands(session, self.post_message)
        self.job_start = JobStarter(self.post_message)
        self.job_path = job_path
        self.poll_interval = poll_interval
        self.snapshot: Snapshot | None = None
        self.job: JobRun | None = None
        self.job_name: str | None = None
        self.job_source: list[str] = []  # the running job's lines, to show the current one
        self.preview: Preview | None = None  # a job planned and shown, waiting for Enter
        self.console: Console | None = None
        self._pause_shown: int | None = None  # the line of the pause last announced
        self._poll_stop = threading.Event()
        self._connecting = False
        self.messages: list[str] = []  # every line of the message log, for scripts and tests
        self.macros = session.config_given.macros if session.config_given is not None else ()
        for i, macro in enumerate(self.macros):  # [[macros]]: keys checked at load (cli/tui.py)
            self._bindings.bind(macro.key, f"macro({i})", macro.name, show=False)
        self._repeats = 0  # the last message again, not written again

    # --- layout ----------------------------------------------------------------------------

    def compose(self) -> ComposeResult:
        yield Header(icon="")
        yield Static("", id="banner")
        with Horizontal(id="top"):
            yield PositionPanel(id="positions")
            yield MachinePanel(id="machine")
        yield JogPanel(id="jog")
        yield JobPanel(id="job")
        yield ConsoleLine(id="console")
        with Horizontal(id="bottom"):
            # wrapped to its width (RichLog renders at ≥ 78)
            yield MessageLog(id="log", wrap=True, min_width=20)
            yield ToolpathView(id="toolpath")
        yield Static(KEY_LINE, id="keys")

    @property
    def _target_label(self) -> str:
        """The board this screen drives: chosen before it opens (the port picker's choice)."""
        target = self.session.target
        assert target is not None
        return target.label

    def on_mount(self) -> None:
        self.app.title = "quadstep"
        self.app.sub_title = self._target_label
        self.query_one("#banner", Static).display = False
        self.query_one(PositionPanel).border_title = "position"
        self.query_one(MachinePanel).border_title = "machine"
        self.query_one(MessageLog).border_title = "messages"
        self.query_one(ToolpathView).border_title = "path (v: fit)"
        self.connect()

    def on_unmount(self) -> None:
        self._poll_stop.set()

    def log_line(self, text: str, error: bool = False) -> None:
        """A line in the message log; the same line again (a held key's repeats) is counted, not
        repeated."""
        if self.messages and self.messages[-1] == text:
            self._repeats += 1
            return
        if self._repeats:
            self._write(
                f"  (the line above {self._repeats} more time{'s' if self._repeats > 1 else ''})",
                False,
            )
            self._repeats = 0
        self.messages.append(text)
        self._write(text, error)

    def _write(self, text: str, error: bool) -> None:
        self.query_one(MessageLog).write(Text(text, style="red" if error else ""))

    def on_note(self, message: Note) -> None:
        self.log_line(message.text, message.error)
        self.refresh_panels()  # what failed may have changed them (a refused jog's "to go")

    def on_descendant_focus(self) -> None:
        self.console_has_keys = isinstance(self.focused, ConsoleLine)

    def on_descendant_blur(self) -> None:
        self.console_has_keys = isinstance(self.focused, ConsoleLine)

    def watch_console_has_keys(self) -> None:
        self.show_keys()
        self.refresh_panels()

    def show_keys(self) -> None:
        """The bottom line: the console's keys while it has them, a job's while one runs, else the
        main keys."""
        line = (
            CONSOLE_KEY_LINE
            if self.console_has_keys
            else JOB_KEY_LINE
            if self.job is not None
            else KEY_LINE
        )
        self.query_one("#keys", Static).update(line)

    def refresh_panels(self) -> None:
        session = self.session
        snapshot = self.snapshot if session.connected else None
        if session.config is not None:
            self.query_one(PositionPanel).show(session.config, snapshot)
        job = self.job.state if self.job is not None else None
        lost = session.machine is not None and session.machine.position_lost
        speeds = session.machine.speed_overrides if session.machine is not None else None
        overrides = (speeds.rapid, speeds.spindle) if speeds is not None else (100, 100)
        self.query_one(MachinePanel).show(
            session.identity, self.snapshot, session.lost, job, lost, overrides
        )
        self.query_one(JogPanel).show(
            session.jogger if session.connected else None, self.console_has_keys
        )
        origin = None
        if snapshot is not None:
            origin = tuple(m - w for m, w in zip(snapshot.position_mm, snapshot.work_mm))
        self.query_one(ToolpathView).show(
            session.config, snapshot.position_mm if snapshot else None, origin
        )

    def check_action(self, action: str, parameters: tuple[Any, ...]) -> bool | None:
        if action == "run_preview":
            return self.preview is not None
        if action == "step_preset":
            return int(parameters[0]) < len(self.session.settings.step_presets)
        if action == "zero":
            config = self.session.config
            return config is None or int(parameters[0]) < len(config.axes)
        return True

    def action_toggle_view(self) -> None:
        self.query_one(ToolpathView).toggle_extent()

    def action_backlash(self) -> None:
        if self._jogger_ready("backlash") is not None:
            self.app.push_screen(BacklashScreen(self.session))

    def action_help(self) -> None:
        self.app.push_screen(HelpScreen(self.session.settings, self.macros))

    # --- connection ------------------------------------------------------------------------

    def connect(self) -> None:
        if self._connecting:
            return
        self._connecting = True
        self._stop_polling()
        self.snapshot = None
        self.refresh_panels()
        self.log_line(f"connecting to {self._target_label}…")
        self.commands.thread(self._connect_worker, "quadstep-connect")

    def _connect_worker(self) -> None:
        try:
            identity = self.session.connect()
        except Exception as exc:  # every failure is shown; the user may retry
            self.session.mark_lost(f"cannot connect: {exc}")
            self.post_message(ConnectionLost(f"cannot connect: {exc}"))
            return
        self.post_message(Connected(identity))

    def on_connected(self, message: Connected) -> None:
        self._connecting = False
        ident = message.identity
        config = self.session.config
        assert config is not None
        self.query_one("#banner", Static).display = False
        self.app.sub_title = (
            f"{self._target_label} · firmware "
            f"{ident.fw_major}.{ident.fw_minor}.{ident.fw_patch} · {len(config.axes)} axes · "
            f"{ident.tick_hz / 1000:g} kHz"
        )
        given = (
            ""
            if self.session.config_given is not None
            else f" (no --config: a default machine, {config.axes[0].steps_per_mm:g} steps/mm)"
        )
        self.log_line(
            f"connected: {_board_name(ident.board)}, {ident.axis_count} axes, "
            f"queue {ident.queue_capacity}{given}"
        )
        machine = self.session.machine
        if machine is not None:
            if machine.notice is not None:  # what it found of the kept state
                self.log_line(machine.notice)
            self.job_start.watch_reports(machine)
            # a job that stopped before its end is named (its journal read off the event loop)
            self.commands.thread(lambda: self.job_start.offer_kept(machine), "quadstep-kept-job")
        self._start_polling()
        self.refresh_panels()

    def on_connection_lost(self, message: ConnectionLost) -> None:
        self._connecting = False
        self._stop_polling()
        banner = self.query_one("#banner", Static)
        banner.update(f"DISCONNECTED: {message.reason}   (Ctrl+R reconnects)")
        banner.display = True
        self.log_line(f"connection lost: {message.reason}", error=True)
        self.refresh_panels()

    def action_reconnect(self) -> None:
        self.job = None
        self.connect()

    def _start_polling(self) -> None:
        stop = self._poll_stop = threading.Event()
        self.commands.thread(lambda: self._poll_worker(stop), "quadstep-poll")

    def _stop_polling(self) -> None:
        self._poll_stop.set()

    def _poll_worker(self, stop: threading.Event) -> None:
        while not stop.is_set():
            try:
                snapshot = self.session.snapshot()
            except LinkError as exc:
                if not stop.is_set():
                    self.post_message(ConnectionLost(str(exc)))
                return
            job = self.job
            self.post_message(StatusUpdate(snapshot, job.progress if job is not None else None))
            stop.wait(self.poll_interval)

    def on_status_update(self, message: StatusUpdate) -> None:
        if not self.session.connected:
            return
        if message.snapshot == self.snapshot and message.job is None:
            return  # nothing changed: no redraw
        self.snapshot = message.snapshot
        if self.job is not None and message.job is not None:
            self.show_job(message.job)
        self.refresh_panels()

    # --- what may run now ------------------------------------------------------------------

    def _jogger_ready(self, what: str) -> Jogger | None:
        jogger = self.session.jogger
        if not self.session.connected or jogger is None:
            self.log_line(f"{what}: not connected (Ctrl+R reconnects)", error=True)
            return None
        if self.job is not None and not (what in AT_A_PAUSE and self.job.gives_way):
            self.log_line(f"{what}: a job is running (Space holds it, Esc stops it)", error=True)
            return None
        return jogger

    def _machine_free(self, what: str) -> Machine | None:
        """The machine, for a job: nothing moving."""
        machine = self.session.machine
        if machine is None or machine.busy:
            self.log_line(f"{what}: the machine is busy", error=True)
            return None
        return machine

    # --- jogging ---------------------------------------------------------------------------

    def action_jog(self, axis: int, direction: int) -> None:
        jogger = self._jogger_ready("jog")
        if jogger is None:
            return
        if axis >= len(jogger.config.axes):
            self.log_line(f"jog: this machine has no axis {AXIS_NAMES[axis]}", error=True)
            return
        if jogger.mode == JogMode.CONTINUOUS:
            self.commands.submit(lambda: jogger.press(axis, direction), "jog")
            return
        step = jogger.queue_step(axis, direction)
        if step is not None:
            self.commands.submit(lambda: _run_step(jogger, step), "jog")
        self.refresh_panels()  # the queued distance

    def key_released(self, key: str) -> None:
        """A jog key let go, where the terminal reports it (kitty.py): a continuous jog stops at
        once."""
        jogger = self.session.jogger
        if jogger is None or jogger.mode != JogMode.CONTINUOUS:
            return
        for name, axis, direction, _, _ in JOG_KEYS:
            if name == key:
                self.commands.thread(
                    _releaser(self.commands, jogger, axis, direction), "quadstep-release"
                )

    def action_step_preset(self, index: int) -> None:
        jogger = self.session.jogger
        if jogger is not None:
            jogger.select_step(index)
            self.refresh_panels()

    def action_z_step(self, delta: int) -> None:
        jogger = self.session.jogger
        if jogger is not None:
            jogger.change_z_step(delta)
            self.refresh_panels()

    def action_speed(self, delta: int) -> None:
        """- and +: the jog speed; while a job runs, its feed override instead."""
        if self.action_feed_override(delta):
            return
        jogger = self.session.jogger
        if jogger is not None:
            jogger.change_speed(delta)
            self.refresh_panels()

    def action_toggle_mode(self) -> None:
        jogger = self.session.jogger
        if jogger is not None:
            if jogger.busy:
                self.log_line("mode: stop the jog first", error=True)
                return
            mode = jogger.toggle_mode()
            self.log_line(f"jog mode: {mode.value}")
            self.refresh_panels()

    def jog_finished(self, result: JogResult) -> None:
        """Session callback, in a worker thread."""
        self.post_message(JogDone(result))

    def on_jog_done(self, message: JogDone) -> None:
        result = message.result
        if result.message:
            self.log_line(result.message, error=bool(result.end is not None and result.end.error))
        if result.kind == JogMode.CONTINUOUS and result.end is not None and not result.end.error:
            config = self.session.config
            assert config is not None
            axis = config.axes[result.axis]
            self.log_line(
                f"{axis.name} at {axis.to_mm(result.position[result.axis]):.3f} mm "
                f"({result.position[result.axis]} steps)"
            )
        self.refresh_panels()

    # --- stopping --------------------------------------------------------------------------

    def action_space(self) -> None:
        """Space: hold or resume a running job; else what Esc does."""
        if not self.action_hold_resume():
            self.action_halt()

    def action_halt(self) -> None:
        """Esc: cancel queued jog presses and bring whatever moves to rest with HOLD (a job ends
        there); a job shown and not started is dropped."""
        self.drop_preview()
        self._drop_queued()
        machine = self.session.machine
        if machine is not None and machine.busy:
            self.commands.thread(
                lambda: self.commands.guarded(lambda: machine.hold("stop"), "stop"),
                "quadstep-halt",
            )

    def _drop_queued(self) -> None:
        self.session.cancel_pending()
        if self.session.jogger is not None:
            self.session.jogger.queue.clear()

    def action_reset(self) -> None:
        """Ctrl+X: the emergency key, an immediate STOP, no deceleration; clears an alarm."""
        self._drop_queued()
        machine = self.session.machine
        if machine is None or not self.session.connected:
            self.log_line("STOP: not connected", error=True)
            return

        def stop() -> None:
            machine.emergency_stop()
            # where the carriage stands, as every position shown (the backlash take-ups excluded)
            self.post_message(Note(f"STOP: stopped at once at steps {list(machine.position)}"))

        self.commands.thread(lambda: self.commands.guarded(stop, "STOP"), "quadstep-reset")

    # --- zeroing ---------------------------------------------------------------------------

    def action_zero(self, axis: int) -> None:
        self._zero([axis])

    def action_zero_all(self) -> None:
        config = self.session.config
        if config is not None:
            self._zero(list(range(len(config.axes))))

    def _zero(self, axes: list[int]) -> None:
        jogger = self._jogger_ready("zero")
        if jogger is None:
            return
        names = ", ".join(jogger.config.axes[a].name for a in axes)

        def zero() -> None:
            machine = jogger.machine
            machine.set_work_zero(axes)
            self.post_message(
                Note(
                    f"zeroed {names} in {machine.coordinates.name} (work offset; "
                    "machine coordinates and soft limits unchanged)"
                )
            )

        self.commands.submit(zero, "zero")

    # --- homing, probing, touching off -----------------------------------------------------

    def action_home(self) -> None:
        """H: home every axis with [axes.homing], in the configured order; each phase goes to the
        log."""
        machine = self.session.machine
        if self._jogger_ready("home") is None or machine is None:
            return
        self.log_line("homing…")

        def progress(text: str) -> None:
            self.post_message(Note(f"home: {text}"))

        def homed() -> str:
            results = home(machine, None, progress)
            return "homed: " + "  ".join(f"{r.name} {r.position_mm:.3f} mm" for r in results)

        self.commands.thread(lambda: self.commands.routine("home", homed), "quadstep-home")

    def action_probe(self, code: str) -> None:
        """P: G38.2 down Z to its travel_min at 1 mm/s (a touch plate); Shift+P: G38.4 up until it
        lets go."""
        machine = self.session.machine
        if self._jogger_ready(f"G{code}") is None or machine is None:
            return
        config = machine.config
        if "Z" not in config.axis_names:
            self.log_line(f"G{code}: this machine has no Z axis", error=True)
            return
        z = config.axis_names.index("Z")
        target = list(machine.position_mm)
        target[z] = config.axes[z].travel_min if code == "38.2" else config.axes[z].travel_max
        self.log_line(f"G{code} Z{target[z]:g} F60…")

        def probed() -> str:
            result = probe(machine, code, target, 1.0)
            if not result.found:
                return f"G{code}: no contact"
            return f"G{code}: contact at Z {result.machine_mm[z]:.4f} mm (step {result.steps[z]})"

        self.commands.thread(lambda: self.commands.routine(f"G{code}", probed), "quadstep-probe")

    def action_touch_off(self) -> None:
        """t: the touch-off screen (Z on a plate, edges, corners, centres: machine/touch_off.py)."""
        machine = self.session.machine
        if self._jogger_ready("touch-off") is None or machine is None:
            return
        if machine.busy and (self.job is None or not self.job.gives_way):
            self.log_line("touch-off: the machine is busy", error=True)
            return

        def note(text: str, error: bool) -> None:
            self.post_message(Note(text, error))

        self.app.push_screen(TouchOffScreen(machine, note, self.commands.sync_jogger))

    # --- jobs: a file, a console line, a macro, the job a crash left ------------------------

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
        self.run_worker(
            lambda: self.job_start.plan_preview(machine, path), thread=True, group="preview"
        )

    def on_preview_ready(self, message: PreviewReady) -> None:
        preview = self.preview = message.preview
        view = self.query_one(ToolpathView)
        view.show_path(preview.toolpath)
        seconds = preview.job.plan.duration_s
        box = preview.toolpath.work_box
        if box is not None and len(box.low) > 1:  # the path view's foot: its size and time
            size = f"{box.high[0] - box.low[0]:.0f}×{box.high[1] - box.low[1]:.0f} mm"
            view.border_subtitle = f"{size} · {seconds:.0f} s · Enter runs"
        for line in message.lines:
            self.log_line(line)
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

        self.commands.thread(
            lambda: self.job_start.run(machine, path.name, plan, preview.source, path),
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

    def action_resume_kept(self) -> None:
        """R: the job kept in the machine's journal, planned from where the machine stands, run."""
        machine = self._machine_free("resume")
        if machine is not None and self._jogger_ready("resume") is not None:
            self.commands.thread(lambda: self.job_start.resume_kept(machine), "quadstep-job")

    def action_console(self) -> None:
        """`:` gives the keys to the console line (Esc gives them back)."""
        if self._jogger_ready("MDI") is not None:
            self.query_one(ConsoleLine).focus()

    def on_console_line_run(self, message: ConsoleLine.Run) -> None:
        """A line typed in the console: planned whole from where the machine stands, then run as a
        job."""
        text = message.text
        self.log_line(f"> {text}")
        found = self._mdi_console("MDI")
        if found is not None:
            machine, console = found
            self._run_typed(
                machine, "MDI", [text], lambda start: console.plan(text, start, machine.coordinates)
            )

    def action_macro(self, index: int) -> None:
        """A [[macros]] key: its lines planned whole from where the machine stands, in the
        console's modal state (as typed lines), then run."""
        macro = self.session.config.macros[index] if self.session.config is not None else None
        if macro is None:
            return
        self.log_line(f"macro {macro.name}: " + " | ".join(macro.gcode))
        what = f"macro {macro.name}"
        found = self._mdi_console(what)
        if found is not None:
            machine, console = found
            lines = list(macro.gcode)

            def plan(start: tuple[int, ...]) -> Job:
                return console.plan_lines(lines, start, machine.coordinates)

            self._run_typed(machine, what, lines, plan)

    def _mdi_console(self, what: str) -> tuple[Machine, Console] | None:
        """The machine, free, and the console's planner for it (its modal state kept from line to
        line)."""
        machine = self._machine_free(what) if self._jogger_ready(what) is not None else None
        if machine is None:
            return None
        if self.console is None or self.console.config is not machine.config:
            self.console = Console(machine.config)
        return machine, self.console

    def _run_typed(self, machine: Machine, what: str, lines: list[str], plan: Plan) -> None:
        """Typed lines (the console's, a macro's) run as a job."""
        self.commands.thread(
            lambda: self.job_start.run(machine, what, plan, lines, typed=True),
            "quadstep-mdi" if what == "MDI" else "quadstep-macro",
        )

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
        outcome = _outcome(message.end, job.progress.line if job is not None else None)
        self.log_line(f"{message.name}: {outcome}", error=bool(message.end.error))
        self.show_keys()
        self.query_one(JobPanel).show(None, None, f"{message.name}: {outcome}")
        self.commands.sync_jogger()

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
            self.commands.thread(job.feed_hold, "quadstep-feed-hold")
            self.log_line("feed hold: g goes on (Space too), Esc stops the job")
        return True

    def action_resume(self) -> None:
        """g: go on after a pause (M0, a tool change) or a feed hold."""
        job = self.job
        if job is None or job.paused_at is None:
            self.log_line("go on: no job waits at a pause", error=True)
        elif not job.resume():
            self.log_line("go on: wait until the machine is at rest", error=True)
        else:
            self._pause_shown = None
            self.log_line("going on")

    # --- overrides -------------------------------------------------------------------------

    def action_feed_override(self, delta: int) -> bool:
        """- + while a job runs: its feed override 10 % lower / higher (within 10–200 %); * (delta
        0) back to 100 %. It applies to what is not yet sent. False: no job."""
        job = self.job
        if job is None:
            return False
        percent = 100 if delta == 0 else clamped(job.feed_override + delta * STEP_PERCENT)
        if percent == job.feed_override:
            if delta:
                self.log_line(f"feed override: {percent} % is the {_bound(delta)}", error=True)
            return True
        try:
            job.set_feed_override(percent)
        except (ValueError, MachineError) as exc:
            self.log_line(f"feed override: {exc}", error=True)
            return True
        self.log_line(f"feed override {percent} %: from the first move not yet sent")
        self.show_job(job.progress)
        return True

    def action_rapid_override(self) -> None:
        """r: the rapids at 100 → 50 → 25 → 100 %."""
        machine = self.session.machine
        if machine is None:
            return
        percent = machine.set_rapid_override(NEXT_RAPID[machine.speed_overrides.rapid])
        self.log_line(f"rapid override {percent} %: {_reach(machine)}")
        self.refresh_panels()

    def action_spindle_override(self, delta: int) -> None:
        """< >: the spindle (or laser power) 10 % lower / higher, within 10–200 %."""
        machine = self.session.machine
        if machine is None:
            return
        now = machine.speed_overrides.spindle
        percent = clamped(now + delta * STEP_PERCENT)
        if percent == now:
            self.log_line(f"spindle override: {percent} % is the {_bound(delta)}", error=True)
            return
        machine.set_spindle_override(percent)
        self.log_line(f"spindle override {percent} %: {_reach(machine)}")
        self.refresh_panels()


def _run_step(jogger: Jogger, step: QueuedStep) -> None:
    """A refused step drops those waiting behind it (they would be refused too): the jog line's "to
    go" goes with them."""
    try:
        jogger.run_queued(step)
    except BaseException:
        jogger.queue.clear()
        raise


def _releaser(commands: Commands, jogger: Jogger, axis: int, direction: int) -> Callable[[], None]:
    """A jog key's release, for a thread of its own (made here, not in the loop over the keys)."""
    return lambda: commands.guarded(lambda: jogger.release(axis, direction), "release")


def _outcome(end: MotionEnd, line: int | None) -> str:
    """How a job ended, for the log and the job line."""
    if end.ended_by == "done":
        return "done"
    if end.error:
        return f"failed: {end.error}"
    return (
        f"stopped near line {line if line is not None else '?'} ({'HOLD' if end.held else 'STOP'})"
    )


def _bound(delta: int) -> str:
    return "most" if delta > 0 else "least"


def _reach(machine: Machine) -> str:
    return "from the first move not yet sent" if machine.busy else "for what runs next"
