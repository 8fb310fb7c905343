"""The dial-indicator wizard: a guided backlash measurement for machines without a probe
(backlash/dial.py).

Set the indicator against the carriage, preload it (p moves the axis toward it), zero it, then
either jog back one motor step at a time until the needle moves, or move back by a distance and type
the reading; the screen says what to do at each step, computes the backlash and writes it after a
confirm.
"""

from __future__ import annotations

import threading

from rich.markup import escape
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.message import Message
from textual.screen import ModalScreen
from textual.widgets import Footer, Input, Static

from ..backlash.dial import DialError, DialResult, from_jog_back, from_reading
from ..config import MachineConfig
from ..link import LinkError
from ..machine import MachineError
from ..machine.raw_moves import RawMoves
from ..machine.units import step_direction
from .confirm import ask_to_write
from .session import Session

PRELOAD_MM = 0.2  # toward the indicator, so that it rests preloaded against the carriage
DISTANCE_MM = 0.5  # the move back, for a reading
FEED = 2.0  # mm/s


class Moved(Message):
    def __init__(self, error: str = "") -> None:
        super().__init__()
        self.error = error


class DialWizard(ModalScreen[None]):
    BINDINGS = [
        Binding("t", "mode", "jog back / reading"),
        Binding("f", "flip", "indicator side"),
        Binding("p", "preload", "preload"),
        Binding("j,left", "jog", "one step back"),
        Binding("enter", "next", "next"),
        Binding("w", "write", "write"),
        Binding("escape", "close", "close"),
    ]

    def __init__(self, session: Session, axis: str) -> None:
        super().__init__()
        self.session = session
        self.axis = axis
        self.mode = "jog"  # or "reading"
        self.side = 1  # the indicator on the axis's + side: preload +, back −
        self.stage = "place"  # place → zero → back (jog) / moved (reading) → done
        self.count = 0  # steps jogged back
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
        self.query_one("#dial-title", Static).update(
            f"[b]Dial indicator[/b]  axis [b]{self.axis}[/b], indicator on its {side} side (f)   "
            "method "
            f"[b]{'jog back' if self.mode == 'jog' else f'move back {DISTANCE_MM:g} mm'}[/b] (t)"
        )
        back = "−" if self.side > 0 else "+"
        text = {
            "place": (
                f"1. Put the indicator against the carriage on its {side} side, square to "
                f"{self.axis}.\n"
                f"2. Press p: {self.axis} moves {PRELOAD_MM:g} mm {side} into it (the preload)."
            ),
            "zero": "3. Zero the indicator, then press Enter.",
            "back": (
                f"4. Press j (or ←) to move {self.axis} {back} one motor step; press Enter as soon "
                f"as the needle moves.   steps so far: [b]{self.count}[/b]"
            ),
            "moved": (
                f"4. {self.axis} moved {DISTANCE_MM:g} mm {back}. Type the indicator's reading "
                "(mm) and press Enter."
            ),
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

    def _move(self, mm: float | None, steps: int = 0) -> None:
        """Move the axis by `mm` (or `steps` motor steps) toward the indicator (+) or away (−), in a
        thread."""
        machine = self.session.machine
        if machine is None or not self.session.connected:
            self.say("not connected", True)
            return
        config = machine.config
        a = config.axis_names.index(self.axis)
        axis = config.axes[a]
        count = steps if mm is None else round(mm * axis.steps_per_mm)
        motor = step_direction(axis, self.side) * count
        self.moving = True

        def run() -> None:
            try:
                with machine.procedure("dial indicator"):
                    RawMoves(machine, FEED).move(a, motor)
            except (LinkError, MachineError) as exc:
                self.post_message(Moved(str(exc)))
            else:
                self.post_message(Moved())

        threading.Thread(target=run, name="quadstep-dial", daemon=True).start()

    def on_moved(self, message: Moved) -> None:
        self.moving = False
        if message.error:
            self.say(f"dial indicator: {message.error}", True)
        self._show()

    def _steps_per_mm(self) -> float:
        config = self.session.config
        assert config is not None
        return config.axes[config.axis_names.index(self.axis)].steps_per_mm

    # --- keys ------------------------------------------------------------------------------

    def action_mode(self) -> None:
        if self.stage in ("place", "zero", "done"):
            self.mode = "reading" if self.mode == "jog" else "jog"
            self._show()

    def action_flip(self) -> None:
        if self.stage in ("place", "done"):
            self.side = -self.side
            self._show()

    def action_preload(self) -> None:
        if self.moving or self.stage not in ("place", "done"):
            return
        self.stage, self.count, self.result = "zero", 0, None
        self._move(PRELOAD_MM)

    def action_jog(self) -> None:
        if self.moving or self.stage != "back":
            return
        self.count += 1
        self._move(None, -1)

    def action_next(self) -> None:
        if self.moving:
            return
        if self.stage == "zero":
            if self.mode == "jog":
                self.stage = "back"
                self._show()
            else:
                self.stage = "moved"
                self._move(-DISTANCE_MM)
        elif self.stage == "back":
            if self.count == 0:
                self.say("jog back first (j): the step that moves the needle counts", True)
                return
            self._done(lambda: from_jog_back(self.count, self._steps_per_mm()))

    def on_input_submitted(self, event: Input.Submitted) -> None:
        if self.stage != "moved" or self.moving:
            return
        try:
            reading = float(event.value.strip().replace(",", "."))
        except ValueError:
            self.say(f"reading {event.value!r}: not a number (mm)", True)
            return
        self._done(lambda: from_reading(DISTANCE_MM, reading, self._steps_per_mm()))

    def _done(self, compute) -> None:  # noqa: ANN001
        try:
            self.result = compute()
        except DialError as exc:
            self.say(str(exc), True)
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
