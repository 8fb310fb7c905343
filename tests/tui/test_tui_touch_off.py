"""The touch-off screen (t) on the example router's simulated machine: Z on the 10 mm plate through
the screen lands the work zero on the surface below the plate (within a step), and the screen fits
80 × 24."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import load_config
from quadstep.machine import state_path
from quadstep.tui import QuadstepApp, Session, Target
from quadstep.tui.touch_off_screen import TouchOffScreen
from test_tui import connected
from tui_helpers import log_text, until
from tui_layout import assert_nothing_cut

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SIM = REPO / "examples" / "router-uno-machine.toml"


def sim_app(emulator_binary: Path, free: bool = True) -> QuadstepApp:
    options: dict[str, object] = {
        "free": free, "binary": emulator_binary, "extra_args": ("--machine", str(SIM))}
    session = Session(Target(emulator=True, emulator_options=options), CONFIG,
                      state_file=state_path(None))
    return QuadstepApp(session, poll_interval=0.05)


async def test_z_touch_off_through_the_screen(emulator_binary: Path) -> None:
    app = sim_app(emulator_binary)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("t")
        await until(pilot, lambda: isinstance(app.screen, TouchOffScreen), what="the screen")
        assert_nothing_cut(app)
        await pilot.press("enter")  # the first routine: Z on a plate; the thickness asked
        field = app.screen.query_one("#touch-off-value")
        assert field.value == "10"  # the configuration's [touch_off] plate (its default)
        await pilot.press("backspace", "backspace", "9", "enter")  # a 9 mm plate, as typed
        await until(pilot, lambda: "Z on a 9 mm plate" in log_text(app), 60, what="the touch-off")
        machine = app.session.machine
        assert machine is not None
        # the plate's top at motor -16000.5 (host -8000.5), met moving down with the motor 1.5 steps
        # past the carriage; the surface 9 mm (3600 steps) below
        surface_steps = -8000.5 - 1.5 - 3600
        zero_steps = machine.coordinates.offset("Z") * 400
        assert abs(zero_steps - surface_steps) <= 1, zero_steps
        assert "Z: second touch at 0.5 mm/s" in str(app.screen.query_one("#touch-off-status").render()) \
            or "work zero in G54" in str(app.screen.query_one("#touch-off-status").render())
        assert_nothing_cut(app)
        await pilot.press("escape")
        await until(pilot, lambda: not isinstance(app.screen, TouchOffScreen), what="closed")


async def test_esc_stops_a_touch_off_with_hold(emulator_binary: Path) -> None:
    app = sim_app(emulator_binary, free=False)  # paced: the first touch takes seconds
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("t", "enter", "enter")
        screen = app.screen
        assert isinstance(screen, TouchOffScreen)
        await until(pilot, lambda: "first touch" in str(screen.query_one("#touch-off-status").render()),
                    what="the first touch")
        await pilot.press("escape")
        await until(pilot, lambda: not screen.running, what="the stop")
        assert "touch-off: stopped (Esc): brought to rest with HOLD, no zero set" in log_text(app)
        machine = app.session.machine
        assert machine is not None and not machine.busy
        assert machine.coordinates.offset("Z") == 0.0  # no zero set
        assert -8000 < machine.sync()[2] < 0  # it stopped on the way down, above the plate
        await pilot.press("escape")
        await until(pilot, lambda: not isinstance(app.screen, TouchOffScreen), what="closed")
