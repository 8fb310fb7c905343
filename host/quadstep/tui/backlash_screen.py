"""The backlash screen (b): measure an axis's backlash with the probe or its limit switch, k tries
shown as they come, the result in mm and steps with its spread, refused over the spread bound,
written to the configuration after a confirm; c calibrates the limit switch's hysteresis (the
backlash known), written the same way; d opens the dial-indicator wizard for machines without a
probe.

The measurement runs in a worker thread (machine/backlash.py) and reports back with messages.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from rich.markup import escape
from textual import work
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
    calibrate_switch,
    known_backlash,
    measure_with_probe,
    measure_with_switch,
    switch_end,
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
            "hysteresis calibrated (c)"
        )
    toward, test = PROBE_SETUP[axis]
    face = f"{'−' if toward > 0 else '+'}{axis}"
    return (
        f"put the probe less than 10 mm outside the target's {face} face and less than 3 mm "
        f"inside its −{test} edge (the corner of those two faces; docs/BACKLASH.md)"
    )


@dataclass(frozen=True)
class Calibration:
    """A switch's hysteresis found with the backlash known (machine/backlash.py's
    calibrate_switch)."""

    axis: str
    hysteresis_mm: float
    backlash_mm: float  # taken off the switch's sum
    steps_per_mm: float


class Calibrated(Message):
    def __init__(self, result: Calibration | None, error: str = "") -> None:
        super().__init__()
        self.result = result
        self.error = error


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
        Binding("m", "method", "method"),
        Binding("minus", "tries(-1)", "tries−", key_display="-", group=TRIES),
        Binding("plus,equals_sign", "tries(1)", "tries+", key_display="+", group=TRIES),
        Binding("enter,s", "start", "measure", key_display="⏎"),
        Binding("c", "calibrate", "calib."),
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
        self.calibration: Calibration | None = None  # the switch's, once calibrated
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
            "Enter: measure   c: calibrate the switch's hysteresis   w: write the result\n"
            "d: dial indicator   Esc: close"
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
        self._begin()
        self.say(f"measuring {self.axis} with the {self.method}, {self.tries} tries…")
        axis, method, tries = self.axis, self.method, self.tries
        self._measure(axis, method, tries)

    def _begin(self) -> None:
        self.running, self.result, self.calibration = True, None, None
        self.lines, self.shown = [], []
        self.query_one("#backlash-result", Static).update("")

    def action_calibrate(self) -> None:
        machine = self.session.machine
        if self.running:
            return
        if machine is None or not self.session.connected:
            self.say("not connected", True)
            return
        axis, tries, config = self.axis, self.tries, machine.config
        try:
            known = known_backlash(config, axis)
        except MachineError as exc:
            self.say(str(exc), True)
            return
        self._begin()
        self.say(
            f"calibrating {axis}'s {switch_end(config, axis)} limit switch ({axis} within 5 mm of "
            f"it, off it), {tries} tries; the backlash {known:.4f} mm (the configuration's) taken "
            "off…"
        )
        self._calibrate(axis, known, tries)

    @work(thread=True, exclusive=True, group="backlash")
    def _calibrate(self, axis: str, known: float, tries: int) -> None:
        machine = self.session.machine
        assert machine is not None

        def progress(text: str) -> None:
            self.post_message(Tried(text))

        try:
            found = calibrate_switch(machine, axis, known, tries=tries, on_progress=progress)
        except (LinkError, MachineError) as exc:
            self.post_message(Calibrated(None, str(exc)))
        else:
            steps = machine.config.axes[machine.config.axis_names.index(axis)].steps_per_mm
            self.post_message(Calibrated(Calibration(axis, found, known, steps)))
        self._resync()

    def _resync(self) -> None:
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self.session.submit(jogger.sync)  # the motors moved under the jogger

    def on_calibrated(self, message: Calibrated) -> None:
        self.running = False
        result = message.result
        if result is None:
            self.say(f"switch {self.axis}: {message.error}", True)
            return
        self.calibration = result
        value = f"{result.hysteresis_mm:.4f} mm"
        rest = (
            f" ({result.hysteresis_mm * result.steps_per_mm:.2f} steps; the backlash "
            f"{result.backlash_mm:.4f} mm taken off)"
        )
        after = "\nw: write it to the configuration (asks first)"
        self.lines.append(f"{result.axis} switch hysteresis: {value}{rest}{after}")
        self.query_one("#backlash-result", Static).update(
            f"{result.axis} switch hysteresis: [b]{value}[/b]{escape(rest)}{after}"
        )

    @work(thread=True, exclusive=True, group="backlash")
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
        self._resync()

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
        if not self.running and self.calibration is not None:
            found = self.calibration
            ask_to_write(
                self,
                self.session.config_path,
                found.axis,
                found.hysteresis_mm,
                self.say,
                self._written,
                key="switch_hysteresis",
            )
            return
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
