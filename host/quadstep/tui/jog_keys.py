"""The machine screen's jog keys: incremental steps (one press, one step; a held key's repeats
beyond what can run soon dropped), continuous jogs, the step and speed presets (X/Y and Z steps
apart), zeroing, the stop keys. Mixed into MachineScreen, whose log, session and worker threads they
use."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from textual.screen import Screen

from ..jog import Jogger, JogMode
from ..jog.step_queue import QueuedStep
from ..link import LinkError, Stopped
from ..machine import JobRun, MachineError
from ..planner.program import JobError
from ..protocol import AXIS_NAMES
from .keys import JOG_KEYS
from .messages import JogDone, Note

if TYPE_CHECKING:
    from .session import Session


# what may run while a job waits at its pause (M0, M6)
AT_A_PAUSE = (
    "jog",
    "zero",
    "G38.2",
    "G38.4",
    "touch-off",
)


class JogKeys(Screen[None]):
    """The part of MachineScreen that jogs, zeroes and stops."""

    session: Session
    job: JobRun | None

    if TYPE_CHECKING:  # MachineScreen's own

        def log_line(self, text: str, error: bool = False) -> None: ...
        def refresh_panels(self) -> None: ...
        def _thread(self, target: Callable[[], object], name: str) -> object: ...
        def action_hold_resume(self) -> bool: ...
        def action_feed_override(self, delta: int) -> bool: ...
        def drop_preview(self) -> bool: ...

    # --- jogging ---------------------------------------------------------------------------

    def check_action(self, action: str, parameters: tuple[Any, ...]) -> bool | None:
        if action == "run_preview":
            return getattr(self, "preview", None) is not None
        if action == "step_preset":
            return int(parameters[0]) < len(self.session.settings.step_presets)
        if action in ("zero",):
            config = self.session.config
            return config is None or int(parameters[0]) < len(config.axes)
        return True

    def _jogger_ready(self, what: str) -> Jogger | None:
        jogger = self.session.jogger
        if not self.session.connected or jogger is None:
            self.log_line(f"{what}: not connected (Ctrl+R reconnects)", error=True)
            return None
        if self.job is not None and not (what in AT_A_PAUSE and self.job.gives_way):
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
        if jogger.mode == JogMode.CONTINUOUS:
            self._command(lambda: jogger.press(axis, direction), "jog")
            return
        step = jogger.queue_step(axis, direction)
        if step is not None:
            self._command(lambda: self._run_step(jogger, step), "jog")
        self.refresh_panels()  # the queued distance

    def _run_step(self, jogger: Jogger, step: QueuedStep) -> None:
        """A refused step drops those waiting behind it (they would be refused too): the jog line's
        "to go" goes with them."""
        try:
            jogger.run_queued(step)
        except BaseException:
            jogger.queue.clear()
            raise

    def key_released(self, key: str) -> None:
        """A jog key let go, where the terminal reports it (kitty.py): a continuous jog stops at
        once."""
        jogger = self.session.jogger
        for name, axis, direction, _, _ in JOG_KEYS:
            if name == key and jogger is not None and jogger.mode == JogMode.CONTINUOUS:
                self._thread(
                    lambda: self._guard_release(jogger, axis, direction), "quadstep-release"
                )

    def _guard_release(self, jogger: Jogger, axis: int, direction: int) -> None:
        try:
            jogger.release(axis, direction)
        except LinkError as exc:
            self.post_message(Note(f"release: {exc}", error=True))

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
            self._thread(lambda: self._guard(lambda: machine.hold("stop"), "stop"), "quadstep-halt")

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
            at = list(machine.position)
            self.post_message(Note(f"STOP: stopped at once at steps {at}"))

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
            self.post_message(
                Note(
                    f"zeroed {names} in {machine.coordinates.name} (work offset; "
                    "machine coordinates and soft limits unchanged)"
                )
            )

        self._command(zero, "zero")

    def _command(self, command: Callable[[], object], what: str) -> None:
        self.session.submit(lambda: self._guard(command, what))

    def _guard(self, command: Callable[[], object], what: str) -> None:
        """Run a command in a worker thread; its failure becomes a red line, never a crash."""
        try:
            command()
        except Stopped:  # a stop key's HOLD ended what this waited for
            self.post_message(Note(f"{what}: stopped: brought to rest with HOLD", error=True))
        except (LinkError, MachineError, ValueError, JobError) as exc:
            self.post_message(Note(f"{what}: {exc}", error=True))
