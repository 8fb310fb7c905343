"""The touch-off screen (t): pick a routine (Z on a plate, an edge, a corner, a bore's or a boss's
centre), give its one value (the plate's thickness, the tool's diameter, the boss's size), Enter
runs it. The routines are the machine layer's (machine/touch_off.py); this screen only asks and
shows. Esc stops a routine that runs, else goes back a step."""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

from textual import work
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.reactive import reactive
from textual.screen import ModalScreen
from textual.widgets import Input, OptionList, Static
from textual.widgets.option_list import Option

from ..link import LinkError, Stopped
from ..machine import Machine, MachineError
from ..machine.touch_off import TouchOff, TouchOffResult
from ..planner.program import JobError


@dataclass(frozen=True)
class Routine:
    key: str
    label: str
    value: str  # what the value asked is ("": none)


ROUTINES = (
    Routine("z", "Z on a touch plate: zero on the surface it lies on", "plate thickness, mm"),
    Routine("x+", "X+ edge: from left of the stock, toward its face", "tool diameter, mm"),
    Routine("x-", "X− edge: from right of the stock", "tool diameter, mm"),
    Routine("y+", "Y+ edge: from in front of the stock", "tool diameter, mm"),
    Routine("y-", "Y− edge: from behind the stock", "tool diameter, mm"),
    Routine("x+y+", "corner from front-left (outside it)", "tool diameter, mm"),
    Routine("x-y+", "corner from front-right", "tool diameter, mm"),
    Routine("x+y-", "corner from back-left", "tool diameter, mm"),
    Routine("x-y-", "corner from back-right", "tool diameter, mm"),
    Routine("bore", "bore centre: from inside it, at the height to probe", ""),
    Routine("boss", "boss centre: from above it", "boss size across, mm"),
)

Note = Callable[[str, bool], None]
STOPPED = "touch-off: stopped (Esc): brought to rest with HOLD, no zero set"


def _sign(key: str, axis: str) -> int:
    return 1 if f"{axis}+" in key else -1


class TouchOffScreen(ModalScreen[None]):
    BINDINGS = [Binding("escape", "back", "back / stop")]

    running: reactive[bool] = reactive(False)
    status: reactive[str] = reactive("")

    def __init__(self, machine: Machine, note: Note, done: Callable[[], None]) -> None:
        """`note` writes a line to the machine screen's log (any thread); `done` after a routine."""
        super().__init__()
        self.machine = machine
        self.note = note
        self.done = done
        self.settings = machine.config.touch_off
        self.routine: Routine | None = None
        self.touch: TouchOff | None = None

    def compose(self) -> ComposeResult:
        with Vertical(id="touch-off"):
            yield Static(
                "Touch-off: ↑ ↓ pick, Enter; then the value, Enter runs; Esc back/stop",
                id="touch-off-help",
            )
            yield OptionList(*(Option(r.label, id=r.key) for r in ROUTINES), id="routines")
            yield Static("", id="touch-off-ask")
            yield Input(id="touch-off-value")
            yield Static("", id="touch-off-status")

    def on_mount(self) -> None:
        self.query_one("#touch-off").border_title = "touch-off"
        self.query_one("#touch-off-value", Input).display = False
        self.query_one(OptionList).focus()

    def watch_status(self, text: str) -> None:
        self.query_one("#touch-off-status", Static).update(text)

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        routine = next(r for r in ROUTINES if r.key == event.option.id)
        self.routine = routine
        if not routine.value:
            self._start(0.0)
            return
        default = (
            self.settings.plate
            if routine.key == "z"
            else self.settings.tool_diameter
            if routine.key != "boss"
            else 0.0
        )
        self.query_one("#touch-off-ask", Static).update(f"{routine.label}\n{routine.value}:")
        field = self.query_one("#touch-off-value", Input)
        field.value = f"{default:g}" if routine.key != "boss" else ""
        field.display = True
        field.focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        try:
            value = float(event.value)
        except ValueError:
            self.status = f"{event.value!r}: give a number of mm"
            return
        boss = self.routine is not None and self.routine.key == "boss"
        if not (0 < value if boss else 0 <= value) or value > 1000:
            least = "more than 0" if boss else "at least 0"
            self.status = f"{value:g}: must be {least} and at most 1000 mm"
            return
        self._start(value)

    def _start(self, value: float) -> None:
        if self.running or self.routine is None:
            return
        self.running = True
        self.query_one("#touch-off-value", Input).display = False
        self.query_one(OptionList).focus()
        self.touch = TouchOff(self.machine, self.settings, self._say)
        self.status = f"{self.routine.label}…"
        self._run(self.touch, self.routine, value)

    @work(thread=True, exclusive=True)
    def _run(self, touch: TouchOff, routine: Routine, value: float) -> None:
        try:
            result = _routine(touch, routine, value)
        except Stopped:  # Esc: the HOLD ended the move under way
            self.app.call_from_thread(self._ended, STOPPED, True)
        except (LinkError, MachineError, JobError) as exc:
            self.app.call_from_thread(self._ended, f"touch-off: {exc}", True)
        else:
            self.app.call_from_thread(self._ended, result.describe(), False)

    def _say(self, text: str) -> None:
        self.app.call_from_thread(setattr, self, "status", text)

    def _ended(self, text: str, error: bool) -> None:
        self.running = False
        self.status = text
        self.note(text, error)
        self.done()

    def action_back(self) -> None:
        if self.running and self.touch is not None:
            # HOLD off the event loop, in a thread of its own: never behind other workers
            threading.Thread(target=self.touch.stop, name="quadstep-touch-off-stop").start()
        elif self.query_one("#touch-off-value", Input).display:
            self.query_one("#touch-off-value", Input).display = False
            self.query_one("#touch-off-ask", Static).update("")
            self.query_one(OptionList).focus()
        else:
            self.dismiss(None)


def _routine(touch: TouchOff, routine: Routine, value: float) -> TouchOffResult:
    key = routine.key
    if key == "z":
        return touch.z(value)
    if key == "bore":
        return touch.bore()
    if key == "boss":
        return touch.boss(value)
    if len(key) == 2:
        return touch.edge(key[0].upper(), _sign(key, key[0]), value / 2)
    return touch.corner(_sign(key, "x"), _sign(key, "y"), value / 2)
