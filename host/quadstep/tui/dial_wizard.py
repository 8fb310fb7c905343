"""The dial-indicator wizard: a guided backlash measurement for machines without a probe
(backlash/dial.py).

Set the indicator against the carriage, preload it (p moves the axis toward it), zero it, then
either jog back (one motor step, or a larger step to get close) until the needle moves, or move back
by the same distance and type the reading; the screen says what to do at each step, computes the
backlash, refuses a result it cannot trust with the reason, and writes it after a confirm. The moves
(machine/dial.py) are longer than the backlash: at least twice the configured one and at least
backlash/dial.py's minimum; + and − change them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

from rich.markup import escape
from textual import work
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.message import Message
from textual.screen import ModalScreen
from textual.widgets import Footer, Input, Static

from ..backlash.dial import JOG_MM, MIN_MOVE_MM, DialError, DialResult, plan
from ..config import MachineConfig
from ..link import LinkError
from ..machine import MachineError
from ..machine.dial import DialMeasurement
from .confirm import ask_to_write
from .session import Session


class Moved(Message):
    def __init__(self, error: str = "") -> None:
        super().__init__()
        self.error = error


BACK = Binding.Group("back", compact=True)
MOVE = Binding.Group("move", compact=True)


class DialWizard(ModalScreen[None]):
    BINDINGS: ClassVar[list[BindingType]] = [
        # grouped and short, so that the key line fits 80 columns (the screen says the rest)
        Binding("t", "mode", "method"),
        Binding("f", "flip", "side"),
        Binding("p", "preload", "preload"),
        Binding("j,left", "jog", "step", group=BACK),
        Binding("k,shift+left", "jog(True)", "0.01 mm", group=BACK),
        Binding("plus,equals_sign", "resize(2)", "longer", key_display="+", group=MOVE),
        Binding("minus", "resize(0.5)", "shorter", key_display="-", group=MOVE),
        Binding("enter", "next", "next", key_display="Enter"),
        Binding("w", "write", "write"),
        Binding("escape", "close", "close", key_display="Esc"),
    ]

    def __init__(self, session: Session, axis: str, jog_mm: float = JOG_MM) -> None:
        super().__init__()
        self.session = session
        self.axis = axis
        self.jog_mm = jog_mm  # the larger jog back (k)
        config = session.config
        self.move_mm = MIN_MOVE_MM  # the preload and the move back; from the configuration below
        if config is not None and axis in config.axis_names:
            try:
                self.move_mm = plan(config.axes[config.axis_names.index(axis)]).move_mm
            except DialError:
                pass  # a short travel: said when the wizard moves
        self.measurement: DialMeasurement | None = None
        self.mode = "jog"  # or "reading"
        self.side = 1  # the indicator on the axis's + side: preload +, back −
        self.stage = "place"  # place → zero → back (jog) / moved (reading) → done
        self.moving = False
        self.result: DialResult | None = None
        self.lines: list[str] = []

    def compose(self) -> ComposeResult:
        with Vertical(id="dial"):
            yield Static(id="dial-title")
            yield Static(id="dial-step")
            yield Input(placeholder="the indicator's reading, mm", id="dial-reading", disabled=True)
            yield Static(id="dial-result")
        yield Footer()

    def on_mount(self) -> None:
        self._show()

    # --- what it shows ---------------------------------------------------------------------

    def _show(self) -> None:
        side = "+" if self.side > 0 else "−"
        move = self.move_mm
        self.query_one("#dial-title", Static).update(
            f"[b]Dial indicator[/b]  axis [b]{self.axis}[/b], indicator on its {side} side (f)   "
            f"method [b]{'jog back' if self.mode == 'jog' else 'move back and read'}[/b] (t)   "
            f"move [b]{move:g} mm[/b] (+ −)"
        )
        back = "−" if self.side > 0 else "+"
        count = self.measurement.count if self.measurement is not None else 0
        text = {
            "place": f"1. Put the indicator against the carriage on its {side} side, square to "
            f"{self.axis}, with {move:g} mm of its travel free.\n"
            f"2. Press p: {self.axis} moves {move:g} mm {side} into it (the preload: longer than "
            "the backlash; + − change it).",
            "zero": "3. Zero the indicator, then press Enter.",
            "back": f"4. Press j (or ←) to move {self.axis} {back} one motor step, k (shift+←) for "
            f"{self.jog_mm:g} mm to get close; press Enter as soon as the needle moves (in a k "
            f"step: refused, repeat with j).   steps so far: [b]{count}[/b]",
            "moved": f"4. {self.axis} moved {move:g} mm {back}. Type the indicator's reading (mm) "
            "and press Enter.",
            "done": "w: write the result to the configuration (asks first)   p: again   Esc: close",
        }[self.stage]
        self.query_one("#dial-step", Static).update(text)
        reading = self.query_one("#dial-reading", Input)
        reading.display = self.stage == "moved"
        reading.disabled = not reading.display  # hidden, it takes no keys
        if reading.display:
            reading.value = ""
            reading.focus()

    def say(self, text: str, error: bool = False) -> None:
        self.lines.append(text)
        self.query_one("#dial-result", Static).update(escape(text))
        if error:
            self.notify(text, severity="error")

    # --- motion ----------------------------------------------------------------------------

    def _run(self, step: Callable[[DialMeasurement], None]) -> None:
        """Run one of the measurement's moves in a thread worker."""
        measurement = self.measurement
        if measurement is None:
            return
        self.moving = True
        self._move(step, measurement)

    @work(thread=True, exclusive=True, group="dial")
    def _move(self, step: Callable[[DialMeasurement], None], measurement: DialMeasurement) -> None:
        try:
            step(measurement)
        except (LinkError, MachineError) as exc:
            self.post_message(Moved(str(exc)))
        else:
            self.post_message(Moved())

    def on_moved(self, message: Moved) -> None:
        self.moving = False
        if message.error:
            self.say(f"dial indicator: {message.error}", True)
        elif self.stage == "back" and self.measurement is not None and self.measurement.overdue:
            self.say(
                f"jogged back {self.measurement.count} steps, more than the preload: the needle "
                "should have moved; the backlash is more than the move (+, then p) or the "
                "indicator does not touch the carriage",
                True,
            )
        self._show()

    # --- keys ------------------------------------------------------------------------------

    def action_mode(self) -> None:
        if self.stage in ("place", "zero", "done"):
            self.mode = "reading" if self.mode == "jog" else "jog"
            self._show()

    def action_flip(self) -> None:
        if self.stage in ("place", "done"):
            self.side = -self.side
            self._show()

    def action_resize(self, factor: float) -> None:
        if self.moving or self.stage not in ("place", "done"):
            return
        self.move_mm = max(MIN_MOVE_MM, self.move_mm * factor)
        self._show()

    def action_preload(self) -> None:
        if self.moving or self.stage not in ("place", "done"):
            return
        machine = self.session.machine
        if machine is None or not self.session.connected:
            self.say("not connected", True)
            return
        try:
            self.measurement = DialMeasurement(
                machine, self.axis, self.side, self.move_mm, self.jog_mm
            )
        except DialError as exc:
            self.say(str(exc), True)
            return
        self.stage, self.result = "zero", None
        self._run(DialMeasurement.preload)

    def action_jog(self, large: bool = False) -> None:
        if self.moving or self.stage != "back":
            return
        self._run(lambda measurement: measurement.jog(large))

    def action_next(self) -> None:
        if self.moving:
            return
        if self.stage == "zero":
            if self.mode == "jog":
                self.stage = "back"
                self._show()
            else:
                self.stage = "moved"
                self._run(DialMeasurement.move_back)
        elif self.stage == "back" and self.measurement is not None:
            if self.measurement.count == 0:
                self.say("jog back first (j): the step that moves the needle counts", True)
                return
            self._done(self.measurement.jogged)

    def on_input_submitted(self, event: Input.Submitted) -> None:
        measurement = self.measurement
        if self.stage != "moved" or self.moving or measurement is None:
            return
        try:
            reading = float(event.value.strip().replace(",", "."))
        except ValueError:
            self.say(f"reading {event.value!r}: not a number (mm)", True)
            return
        self._done(lambda: measurement.read(reading))

    def _done(self, compute: Callable[[], DialResult]) -> None:
        try:
            self.result = compute()
        except DialError as exc:
            self.stage = "done"  # refused: p measures again
            self.say(f"{self.axis}: {exc}", True)
            self._show()
            return
        self.stage = "done"
        self.say(f"{self.axis} backlash: {self.result.mm:.4f} mm ({self.result.steps:g} steps)")
        self._show()

    def action_write(self) -> None:
        if self.result is None:
            self.say("nothing to write yet", True)
            return
        ask_to_write(
            self, self.session.config_path, self.axis, self.result.mm, self.say, self._written
        )

    def _written(self, config: MachineConfig) -> None:
        self.session.config_given = config

    def action_close(self) -> None:
        if self.moving:
            return
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self.session.submit(jogger.sync)  # the motors moved under the jogger
        self.dismiss(None)
