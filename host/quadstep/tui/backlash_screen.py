"""The backlash screen (b): measure an axis's backlash with the probe or its limit switch, k tries
shown as they come, the result in mm and steps with its spread, refused over the spread bound,
written to the configuration after a confirm; d opens the dial-indicator wizard for machines without
a probe.

The measurement runs in a worker thread (machine/backlash.py) and reports back with messages.
"""

from __future__ import annotations

import threading
from typing import ClassVar

from rich.markup import escape
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical
from textual.message import Message
from textual.screen import ModalScreen
from textual.widgets import Footer, Static

from ..config import MachineConfig
from ..link import LinkError
from ..machine import MachineError
from ..machine.backlash import (
    PROBE_SETUP,
    Measurement,
    measure_with_probe,
    measure_with_switch,
)
from .confirm import ask_to_write
from .dial_wizard import DialWizard
from .session import Session

METHODS = ("probe", "switch")
AXIS = Binding.Group("axis", compact=True)
TRIES = Binding.Group("tries", compact=True)


def placement(axis: str, method: str) -> str:
    """Where to put the probe (or the axis) before measuring, for the screen's defaults."""
    if method == "switch":
        return (
            f"{axis} within 5 mm of its homing end's limit switch, off it; the switch's "
            "hysteresis calibrated (quadstep backlash calibrate-switch)"
        )
    toward, test = PROBE_SETUP[axis]
    face = f"{'−' if toward > 0 else '+'}{axis}"
    return (
        f"put the probe less than 10 mm outside the target's {face} face and less than 3 mm "
        f"inside its −{test} edge (the corner of those two faces; docs/BACKLASH.md)"
    )


class Tried(Message):
    def __init__(self, text: str) -> None:
        super().__init__()
        self.text = text


class Measured(Message):
    def __init__(self, result: Measurement | None, error: str = "") -> None:
        super().__init__()
        self.result = result
        self.error = error


class BacklashScreen(ModalScreen[None]):
    BINDINGS: ClassVar[list[BindingType]] = [
        # grouped, so that the key line fits 80 columns
        Binding("x", "axis('X')", "X", group=AXIS),
        Binding("y", "axis('Y')", "Y", group=AXIS),
        Binding("z", "axis('Z')", "Z", group=AXIS),
        Binding("m", "method", "probe/switch"),
        Binding("minus", "tries(-1)", "tries−", key_display="-", group=TRIES),
        Binding("plus,equals_sign", "tries(1)", "tries+", key_display="+", group=TRIES),
        Binding("enter,s", "start", "measure", key_display="Enter"),
        Binding("w", "write", "write"),
        Binding("d", "dial", "dial"),
        Binding("escape", "close", "close", key_display="Esc"),
    ]

    def __init__(self, session: Session, max_spread: float = 0.01) -> None:
        super().__init__()
        self.session = session
        self.max_spread = max_spread  # mm: a result whose tries spread more is refused
        config = session.config
        self.axis = config.axis_names[0] if config is not None else "X"
        self.method = "probe"
        self.tries = 5
        self.running = False
        self.result: Measurement | None = None
        self.lines: list[str] = []  # every line said, the result's too, for scripts and tests
        self.shown: list[str] = []  # the lines under the tries (the result has its own place)

    def compose(self) -> ComposeResult:
        with Vertical(id="backlash"):
            yield Static(id="backlash-setup")
            yield Static(id="backlash-tries")
            yield Static(id="backlash-result")
        yield Footer()

    def on_mount(self) -> None:
        self._show_setup()

    # --- what it shows ---------------------------------------------------------------------

    def _show_setup(self) -> None:
        self.query_one("#backlash-setup", Static).update(
            f"[b]Backlash[/b]  axis [b]{self.axis}[/b] (x y z)   method [b]{self.method}[/b] (m): "
            f"{escape(placement(self.axis, self.method))}\n"
            f"tries [b]{self.tries}[/b] (- +)   "
            f"refused when they spread more than {self.max_spread:g} mm\n"
            "Enter: measure   w: write the result   d: dial indicator   Esc: close"
        )

    def say(self, text: str, error: bool = False) -> None:
        self.lines.append(text)
        self.shown.append(text)
        shown = "\n".join(escape(line) for line in self.shown[-10:])
        self.query_one("#backlash-tries", Static).update(shown)
        if error:
            self.notify(text, severity="error")

    # --- keys ------------------------------------------------------------------------------

    def action_axis(self, name: str) -> None:
        config = self.session.config
        if self.running or config is None or name not in config.axis_names:
            return
        self.axis = name
        self._show_setup()

    def action_method(self) -> None:
        if not self.running:
            self.method = METHODS[(METHODS.index(self.method) + 1) % len(METHODS)]
            self._show_setup()

    def action_tries(self, delta: int) -> None:
        if not self.running:
            self.tries = min(20, max(1, self.tries + delta))
            self._show_setup()

    def action_start(self) -> None:
        machine = self.session.machine
        if self.running:
            return
        if machine is None or not self.session.connected:
            self.say("not connected", True)
            return
        self.running, self.result = True, None
        self.lines, self.shown = [], []
        self.query_one("#backlash-result", Static).update("")
        self.say(f"measuring {self.axis} with the {self.method}, {self.tries} tries…")
        axis, method, tries = self.axis, self.method, self.tries
        threading.Thread(
            target=lambda: self._measure(axis, method, tries), name="quadstep-backlash", daemon=True
        ).start()

    def _measure(self, axis: str, method: str, tries: int) -> None:
        machine = self.session.machine
        assert machine is not None

        def progress(text: str) -> None:
            self.post_message(Tried(text))

        try:
            if method == "switch":
                result = measure_with_switch(
                    machine, axis, tries=tries, max_spread=self.max_spread, on_progress=progress
                )
            else:
                toward, test = PROBE_SETUP[axis]
                result = measure_with_probe(
                    machine,
                    axis,
                    toward=toward,
                    test=test,
                    test_toward=1,
                    tries=tries,
                    max_spread=self.max_spread,
                    on_progress=progress,
                )
        except (LinkError, MachineError) as exc:
            self.post_message(Measured(None, str(exc)))
        else:
            self.post_message(Measured(result))
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self.session.submit(jogger.sync)  # the motors moved under the jogger

    def on_tried(self, message: Tried) -> None:
        self.say(message.text)

    def on_measured(self, message: Measured) -> None:
        self.running = False
        result = message.result
        if result is None:
            self.say(f"backlash {self.axis}: {message.error}", True)
            return
        value = f"{result.mm:.4f} mm"
        rest = (
            f" ({result.steps:g} steps), spread {result.spread_steps:g} steps "
            f"({result.spread_mm:.4f} mm) over {len(result.tries)} tries"
        )
        if result.accepted:
            self.result = result
            after = "\nw: write it to the configuration (asks first)"
            marked = after
        else:
            after = f"\nrefused: {result.refused} (check the setup, then measure again)"
            marked = (
                f"\n[b]refused[/b]: {escape(result.refused)} (check the setup, then measure again)"
            )
        self.lines.append(f"{result.axis} backlash: {value}{rest}{after}")  # plain, for scripts
        self.query_one("#backlash-result", Static).update(
            f"{result.axis} backlash: [b]{value}[/b]{escape(rest)}{marked}"
        )

    def action_write(self) -> None:
        if self.running or self.result is None:
            self.say("nothing to write: measure first (a refused result is not written)", True)
            return
        ask_to_write(
            self,
            self.session.config_path,
            self.result.axis,
            self.result.mm,
            self.say,
            self._written,
        )

    def _written(self, config: MachineConfig) -> None:
        self.session.config_given = config  # the next connection compensates with it

    def action_dial(self) -> None:
        if not self.running:
            self.app.push_screen(DialWizard(self.session, self.axis))

    def action_close(self) -> None:
        if not self.running:
            self.dismiss(None)
