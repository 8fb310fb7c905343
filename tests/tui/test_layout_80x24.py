"""Every screen of the TUI at 80 × 24 with no line cut and no widget off the screen: the machine
screen (incremental and continuous, with steps still to go, a job at a pause, the console with the
keys), help, the job dialog, the backlash screen, the dial-indicator wizard, the touch-off screen
and the port picker. Each is checked once it shows what it is about (no timing)."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from quadstep.tui import QuadstepApp, Session
from quadstep.tui.backlash_screen import BacklashScreen
from quadstep.tui.dial_wizard import DialWizard
from quadstep.tui.help import HelpScreen
from quadstep.tui.job_dialog import JobDialog
from quadstep.tui.port_picker import PortChoice, PortPicker
from quadstep.tui.touch_off_screen import TouchOffScreen
from test_tui import connected, make_app, shown
from tui_helpers import HELD_UNTIL_STOPPED, log_text, until
from tui_layout import assert_nothing_cut

SIZE = (80, 24)


async def test_the_machine_screen_and_its_dialogs(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "paused.gcode"
    job.write_text("G21 G90\nG1 X1 F600\nM0\nG1 X2\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job),
                   settings=HELD_UNTIL_STOPPED)
    async with app.run_test(size=SIZE) as pilot:
        await connected(pilot, app)
        assert_nothing_cut(app)
        await pilot.press("4", "plus", "plus")  # the widest step and speed
        await pilot.press("c")
        assert_nothing_cut(app)
        await pilot.press("c", ":")  # the console has the keys
        assert_nothing_cut(app)
        await pilot.press("escape", "question_mark")
        assert isinstance(app.screen, HelpScreen)
        assert_nothing_cut(app)
        await pilot.press("escape", "o")
        assert isinstance(app.screen, JobDialog)
        assert_nothing_cut(app)
        await pilot.press("escape", "t")
        await until(pilot, lambda: isinstance(app.screen, TouchOffScreen), what="touch-off")
        assert_nothing_cut(app)
        await pilot.press("escape", "b")
        await until(pilot, lambda: isinstance(app.screen, BacklashScreen), what="backlash")
        assert_nothing_cut(app)
        await pilot.press("d")
        await until(pilot, lambda: isinstance(app.screen, DialWizard), what="dial wizard")
        assert_nothing_cut(app)
        await pilot.press("escape")
        await until(pilot, lambda: isinstance(app.screen, BacklashScreen), what="back")
        await pilot.press("escape")
        await until(pilot, lambda: app.screen is app.machine, what="the machine screen")
        # a job shown before it runs, then at its M0: the job line and the job's keys
        await pilot.press("o", "enter")
        await until(pilot, lambda: app.machine.preview is not None, what="the job shown")
        assert "Enter runs it, Esc drops it" in str(app.machine.query_one("#job-label").render())
        assert_nothing_cut(app)
        await pilot.press("enter")
        await until(pilot, lambda: app.machine.job is not None
                    and app.machine.job.paused_at is not None, what="the pause")
        await until(pilot, lambda: "PAUSED at 3" in str(app.machine.query_one("#job-label").render()),
                    what="the job line")
        assert_nothing_cut(app)
        await pilot.press("g")
        await until(pilot, lambda: "paused.gcode: done" in log_text(app), what="the job's end")
        await shown(pilot, app, (160, 0, 0))
        assert_nothing_cut(app)


async def test_the_port_picker(machine: MachineConfig) -> None:
    ports = [PortChoice("/dev/ttyACM0", "Arduino Uno", "Arduino Uno (ttyACM0) with a long name"),
             PortChoice("/dev/ttyUSB0", None, "USB-Serial Controller D")]
    app = QuadstepApp(Session(None, machine), ports=ports)
    async with app.run_test(size=SIZE) as pilot:
        await until(pilot, lambda: isinstance(app.screen, PortPicker), what="the picker")
        assert_nothing_cut(app)
