"""The machine screen: what the machine does, and the keys that jog it, zero it and run jobs.

Nothing here waits on the serial line: connecting, polling, jogging and jobs
run in worker threads and report back with messages (messages.py).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.reactive import reactive
from textual.widgets import Header, Static

from ..jog import JogResult
from ..link import LinkError, Stopped
from ..machine import JobRun, Machine, MachineError
from ..machine.homing import home
from ..machine.probing import probe
from ..mdi import Console
from ..planner.program import JobError
from ..protocol import Board
from .backlash_screen import BacklashScreen
from .console import ConsoleLine
from .help import HelpScreen
from .jobs import JobKeys
from .jog_keys import JogKeys
from .keys import CONSOLE_KEY_LINE, JOB_KEY_LINE, KEY_LINE, bindings
from .messages import Connected, ConnectionLost, JogDone, Note, StatusUpdate
from .override_keys import OverrideKeys
from .panels import JobPanel, JogPanel, MachinePanel, MessageLog, PositionPanel
from .session import Session, Snapshot
from .toolpath_view import ToolpathView
from .touch_off_screen import TouchOffScreen

POLL_INTERVAL = 0.1  # s between STATUS requests


def _board_name(board: int) -> str:
    try:
        return Board(board).name.lower()
    except ValueError:
        return f"board {board}"


class MachineScreen(JobKeys, JogKeys, OverrideKeys):
    BINDINGS = bindings(9)  # step keys beyond the presets are hidden by check_action
    AUTO_FOCUS = ""  # nothing: every key jogs until `:` focuses the console line
    console_has_keys: reactive[bool] = reactive(False)  # the key line and the jog line say so

    def __init__(
        self, session: Session, job_path: str = "", poll_interval: float = POLL_INTERVAL
    ) -> None:
        super().__init__()
        self.session = session
        session.on_jog = self.jog_finished
        self.job_path = job_path
        self.poll_interval = poll_interval
        self.snapshot: Snapshot | None = None
        self.job: JobRun | None = None
        self.job_name: str | None = None
        self.job_source: list[str] = []  # the running job's lines, to show the current one
        self.console: Console | None = None
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

    # --- connection ------------------------------------------------------------------------

    def connect(self) -> None:
        if self._connecting:
            return
        self._connecting = True
        self._stop_polling()
        self.snapshot = None
        self.refresh_panels()
        self.log_line(f"connecting to {self._target_label}…")
        self._thread(self._connect_worker, "quadstep-connect")

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
        if self.session.machine is not None:
            if self.session.machine.notice is not None:  # what it found of the kept state
                self.log_line(self.session.machine.notice)
            self.watch_reports(self.session.machine)
            self.offer_kept_job(self.session.machine)
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

    def _start_polling(self) -> None:
        stop = self._poll_stop = threading.Event()
        self._thread(lambda: self._poll_worker(stop), "quadstep-poll")

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

    # --- homing and probing -------------------------------------------------------------

    def action_home(self) -> None:
        """H: home every axis with [axes.homing], in the configured order; each phase goes to the
        log."""
        if self._jogger_ready("home") is None or self.session.machine is None:
            return
        machine = self.session.machine
        self.log_line("homing…")
        self._thread(
            lambda: self._routine(machine, "home", lambda: self._homed(machine)), "quadstep-home"
        )

    def action_probe(self, code: str) -> None:
        """P: G38.2 down Z to its travel_min at 1 mm/s (a touch plate); Shift+P: G38.4 up until it
        lets go."""
        if self._jogger_ready(f"G{code}") is None or self.session.machine is None:
            return
        machine = self.session.machine
        config = machine.config
        if "Z" not in config.axis_names:
            self.log_line(f"G{code}: this machine has no Z axis", error=True)
            return
        z = config.axis_names.index("Z")
        target = list(machine.position_mm)
        target[z] = config.axes[z].travel_min if code == "38.2" else config.axes[z].travel_max
        self.log_line(f"G{code} Z{target[z]:g} F60…")

        def run() -> str:
            result = probe(machine, code, target, 1.0)
            return (
                f"G{code}: contact at Z {result.machine_mm[z]:.4f} mm (step {result.steps[z]})"
                if result.found
                else f"G{code}: no contact"
            )

        self._thread(lambda: self._routine(machine, f"G{code}", run), "quadstep-probe")

    def action_touch_off(self) -> None:
        """t: the touch-off screen (Z on a plate, edges, corners, centres: machine/touch_off.py)."""
        if self._jogger_ready("touch-off") is None or self.session.machine is None:
            return
        if self.session.machine.busy and (self.job is None or not self.job.gives_way):
            self.log_line("touch-off: the machine is busy", error=True)
            return

        def note(text: str, error: bool) -> None:
            self.post_message(Note(text, error))

        def done() -> None:
            jogger = self.session.jogger
            if jogger is not None and self.session.connected:
                self._command(jogger.sync, "sync")

        self.app.push_screen(TouchOffScreen(self.session.machine, note, done))

    def _homed(self, machine: Machine) -> str:
        def progress(text: str) -> None:
            self.post_message(Note(f"home: {text}"))

        results = home(machine, None, progress)
        return "homed: " + "  ".join(f"{r.name} {r.position_mm:.3f} mm" for r in results)

    def _routine(self, machine: Machine, what: str, body: Callable[[], str]) -> None:
        """A homing or probing routine in a worker thread: its outcome to the log, then the jogger
        resyncs."""
        try:
            self.post_message(Note(body()))
        except Stopped:  # Esc: the HOLD ended the move under way
            self.post_message(Note(f"{what}: stopped (Esc): brought to rest with HOLD", True))
        except (LinkError, MachineError, JobError) as exc:
            self.post_message(Note(f"{what}: {exc}", error=True))
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self._command(jogger.sync, "sync")

    # --- the rest --------------------------------------------------------------------------

    def on_note(self, message: Note) -> None:
        self.log_line(message.text, message.error)
        self.refresh_panels()  # what failed may have changed them (a refused jog's "to go")

    def action_reconnect(self) -> None:
        if self.job is not None:
            self.job = None
        self.connect()

    def action_toggle_view(self) -> None:
        self.query_one(ToolpathView).toggle_extent()

    def action_backlash(self) -> None:
        if self._jogger_ready("backlash") is not None:
            self.app.push_screen(BacklashScreen(self.session))

    def action_help(self) -> None:
        self.app.push_screen(HelpScreen(self.session.settings, self.macros))

    def jog_finished(self, result: JogResult) -> None:
        """Session callback, in a worker thread."""
        self.post_message(JogDone(result))

    def _thread(self, target: Callable[[], object], name: str) -> threading.Thread:
        """A thread of its own for what runs long (polling, a job) or must never wait (a stop):
        Textual's thread workers share the event loop's default executor, a handful of threads,
        where a HOLD could queue behind a job. Short work uses run_worker (the job preview)."""
        thread = threading.Thread(target=target, name=name, daemon=True)
        thread.start()
        return thread
