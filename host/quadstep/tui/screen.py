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
from textual.widgets import Footer, Header, Static

from ..jog import JogMode, Jogger, JogResult
from ..link import LinkError
from ..machine import JobRun, Machine, MachineError
from ..machine.homing import home
from ..machine.probing import probe
from ..planner.program import JobError
from ..protocol import AXIS_NAMES, Board
from .help import HelpScreen
from .jobs import JobKeys
from .keys import bindings
from .messages import Connected, ConnectionLost, JogDone, Note, StatusUpdate
from .panels import JobPanel, JogPanel, MachinePanel, MessageLog, PositionPanel
from .session import Session, Snapshot

POLL_INTERVAL = 0.1  # s between STATUS requests


def _board_name(board: int) -> str:
    try:
        return Board(board).name.lower()
    except ValueError:
        return f"board {board}"


class MachineScreen(JobKeys):
    BINDINGS = bindings(9)  # step keys beyond the presets are hidden by check_action

    def __init__(self, session: Session, job_path: str = "", poll_interval: float = POLL_INTERVAL) -> None:
        super().__init__()
        self.session = session
        session.on_jog = self.jog_finished
        self.job_path = job_path
        self.poll_interval = poll_interval
        self.snapshot: Snapshot | None = None
        self.job: JobRun | None = None
        self.job_name: str | None = None
        self._poll_stop = threading.Event()
        self._connecting = False
        self.messages: list[str] = []  # every line of the message log, for scripts and tests

    # --- layout ----------------------------------------------------------------------------

    def compose(self) -> ComposeResult:
        yield Header(icon="")
        yield Static("", id="banner")
        with Horizontal(id="top"):
            yield PositionPanel(id="positions")
            yield MachinePanel(id="machine")
        yield JogPanel(id="jog")
        yield JobPanel(id="job")
        yield MessageLog(id="log", wrap=True)
        yield Footer()

    def on_mount(self) -> None:
        self.app.title = "quadstep"
        self.app.sub_title = self.session.target.label
        self.query_one("#banner", Static).display = False
        self.query_one(PositionPanel).border_title = "position"
        self.query_one(MachinePanel).border_title = "machine"
        self.query_one(MessageLog).border_title = "messages"
        self.connect()

    def on_unmount(self) -> None:
        self._poll_stop.set()

    def log_line(self, text: str, error: bool = False) -> None:
        self.messages.append(text)
        self.query_one(MessageLog).write(Text(text, style="red" if error else ""))

    def refresh_panels(self) -> None:
        session = self.session
        if session.config is not None:
            self.query_one(PositionPanel).show(session.config, self.snapshot if session.connected else None)
        self.query_one(MachinePanel).show(session.identity, self.snapshot, session.lost)
        self.query_one(JogPanel).show(session.jogger if session.connected else None)

    # --- connection ------------------------------------------------------------------------

    def connect(self) -> None:
        if self._connecting:
            return
        self._connecting = True
        self._stop_polling()
        self.snapshot = None
        self.refresh_panels()
        self.log_line(f"connecting to {self.session.target.label}…")
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
            f"{self.session.target.label} · firmware {ident.fw_major}.{ident.fw_minor}.{ident.fw_patch} · "
            f"{len(config.axes)} axes · {ident.tick_hz / 1000:g} kHz"
        )
        given = "" if self.session.config_given is not None else " (no --config: default 80 steps/mm, ±1000 mm)"
        self.log_line(f"connected: {_board_name(ident.board)}, {ident.axis_count} axes, "
                      f"queue {ident.queue_capacity}{given}")
        if self.session.machine is not None:
            self.watch_reports(self.session.machine)
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
            self.query_one(JobPanel).show(self.job_name, message.job)
        self.refresh_panels()

    # --- jogging ---------------------------------------------------------------------------

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        if action == "step_preset":
            return int(parameters[0]) < len(self.session.settings.step_presets)  # type: ignore[call-overload]
        if action in ("zero",):
            config = self.session.config
            return config is None or int(parameters[0]) < len(config.axes)  # type: ignore[call-overload]
        return True

    def _jogger_ready(self, what: str) -> Jogger | None:
        jogger = self.session.jogger
        if not self.session.connected or jogger is None:
            self.log_line(f"{what}: not connected (Ctrl+R reconnects)", error=True)
            return None
        if self.job is not None:
            self.log_line(f"{what}: a job is running (Space holds it, Esc stops it)", error=True)
            return None
        return jogger

    def action_jog(self, axis: int, direction: int) -> None:
        jogger = self._jogger_ready("jog")
        if jogger is None:
            return
        if axis >= len(jogger.config.axes):
            self.log_line(f"jog: this machine has no axis {AXIS_NAMES[axis]}", error=True)
            return
        self._command(lambda: jogger.jog(axis, direction), "jog")

    def action_step_preset(self, index: int) -> None:
        jogger = self.session.jogger
        if jogger is not None:
            jogger.select_step(index)
            self.refresh_panels()

    def action_speed(self, delta: int) -> None:
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

    def on_jog_done(self, message: JogDone) -> None:
        result = message.result
        if result.message:
            self.log_line(result.message, error=bool(result.end is not None and result.end.error))
        if result.kind == JogMode.CONTINUOUS and result.end is not None and not result.end.error:
            config = self.session.config
            assert config is not None
            axis = config.axes[result.axis]
            self.log_line(f"{axis.name} at {axis.to_mm(result.position[result.axis]):.3f} mm "
                          f"({result.position[result.axis]} steps)")

    def action_space(self) -> None:
        """Space: hold or resume a running job; else what Esc does."""
        if not self.action_hold_resume():
            self.action_halt()

    def action_halt(self) -> None:
        """Esc: cancel queued jog presses and bring whatever moves to rest with HOLD (a job ends there)."""
        self.session.cancel_pending()
        machine = self.session.machine
        if machine is not None and machine.busy:
            self._thread(lambda: self._guard(lambda: machine.hold("stop"), "stop"), "quadstep-halt")

    def action_reset(self) -> None:
        """Ctrl+X: the emergency key, an immediate STOP, no deceleration; clears an alarm."""
        self.session.cancel_pending()
        machine = self.session.machine
        if machine is None or not self.session.connected:
            self.log_line("STOP: not connected", error=True)
            return

        def stop() -> None:
            status = machine.emergency_stop()
            self.post_message(Note(f"STOP: stopped at once at steps {list(status.position)}"))

        self._thread(lambda: self._guard(stop, "STOP"), "quadstep-reset")

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
            self.post_message(Note(f"zeroed {names} in {machine.coordinates.name} (work offset; "
                                   "machine coordinates and soft limits unchanged)"))

        self._command(zero, "zero")

    def _command(self, command: Callable[[], object], what: str) -> None:
        self.session.submit(lambda: self._guard(command, what))

    def _guard(self, command: Callable[[], object], what: str) -> None:
        """Run a command in a worker thread; its failure becomes a red line, never a crash."""
        try:
            command()
        except (LinkError, MachineError, ValueError, JobError) as exc:
            self.post_message(Note(f"{what}: {exc}", error=True))

    # --- homing and probing -------------------------------------------------------------

    def action_home(self) -> None:
        """H: home every axis with [axes.homing], in the configured order; each phase goes to the log."""
        if self._jogger_ready("home") is None or self.session.machine is None:
            return
        machine = self.session.machine
        self.log_line("homing…")
        self._thread(lambda: self._routine(machine, "home", lambda: self._homed(machine)), "quadstep-home")

    def action_probe(self, code: str) -> None:
        """P: G38.2 down Z to its travel_min at 1 mm/s (a touch plate); Shift+P: G38.4 up until it lets go."""
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
            return (f"G{code}: contact at Z {result.machine_mm[z]:.4f} mm (step {result.steps[z]})"
                    if result.found else f"G{code}: no contact")

        self._thread(lambda: self._routine(machine, f"G{code}", run), "quadstep-probe")

    def _homed(self, machine: Machine) -> str:
        results = home(machine, None, lambda text: self.post_message(Note(f"home: {text}")))
        return "homed: " + "  ".join(f"{r.name} {r.position_mm:.3f} mm" for r in results)

    def _routine(self, machine: Machine, what: str, body: Callable[[], str]) -> None:
        """A homing or probing routine in a worker thread: its outcome to the log, then the jogger resyncs."""
        try:
            self.post_message(Note(body()))
        except (LinkError, MachineError, JobError) as exc:
            self.post_message(Note(f"{what}: {exc}", error=True))
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self._command(jogger.sync, "sync")

    # --- the rest --------------------------------------------------------------------------

    def on_note(self, message: Note) -> None:
        self.log_line(message.text, message.error)

    def action_reconnect(self) -> None:
        if self.job is not None:
            self.job = None
        self.connect()

    def action_help(self) -> None:
        self.app.push_screen(HelpScreen(self.session.settings))

    def jog_finished(self, result: JogResult) -> None:
        """Session callback, in a worker thread."""
        self.post_message(JogDone(result))

    def _thread(self, target: Callable[[], object], name: str) -> threading.Thread:
        thread = threading.Thread(target=target, name=name, daemon=True)
        thread.start()
        return thread
