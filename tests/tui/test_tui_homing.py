"""The TUI's h and p keys, against the emulator with the example router's simulated machine: homing logs each
phase and ends homed, probing logs the exact contact step."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import load_config
from quadstep.tui import QuadstepApp, Session, Target
from tui_helpers import log_text, until

REPO = Path(__file__).resolve().parents[2]


async def test_home_and_probe_keys(emulator_binary: Path) -> None:
    config = load_config(REPO / "examples" / "router-uno.toml")
    options = {"free": True, "binary": emulator_binary,
               "extra_args": ("--machine", str(REPO / "examples" / "router-uno-machine.toml"))}
    app = QuadstepApp(Session(Target(emulator=True, emulator_options=options), config), poll_interval=0.05)
    async with app.run_test(size=(100, 32)) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")
        await pilot.press("p")
        await until(pilot, lambda: "G38.2: contact at Z" in log_text(app), 30, "the probe's contact")
        assert "G38.2: contact at Z -20.0050 mm (step -8002)" in log_text(app)
        await pilot.press("h")
        await until(pilot, lambda: "homed:" in log_text(app), 60, "homing")
        text = log_text(app)
        assert "home: Z: seeking the switch" in text and "home: X: locating the switch" in text
        assert "homed: Z 0.000 mm  X 0.000 mm  Y 0.000 mm" in text  # the travel's ends, clear of the switches
        assert app.session.machine is not None and app.session.machine.homed
