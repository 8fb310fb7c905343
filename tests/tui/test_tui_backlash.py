"""The TUI's backlash screen (b) and dial-indicator wizard, against the emulator with a simulated machine whose
backlash only it knows: the probe's result within a step, its tries shown as they come; a scattered result
refused; the wizard's value from scripted jogs and readings; nothing written without the confirm; at 80×24."""

from __future__ import annotations

import shutil
from pathlib import Path

from backlash_rig import rig_text
from quadstep.config import load_config
from quadstep.config_file import set_backlash
from quadstep.tui import QuadstepApp, Session, Target
from quadstep.tui.backlash_screen import BacklashScreen
from quadstep.tui.confirm import ConfirmScreen
from quadstep.tui.dial_wizard import DialWizard
from textual.widgets import Static
from tui_helpers import until

REPO = Path(__file__).resolve().parents[2]
SIZE = (80, 24)


def app_on(tmp_path: Path, emulator_binary: Path, sim: str, mm: float = 0.05) -> tuple[QuadstepApp, Path]:
    path = tmp_path / "machine.toml"
    shutil.copy(REPO / "examples" / "router-uno.toml", path)
    path.write_text(path.read_text().replace("debounce_ms = 0.5", "debounce_ms = 2"))
    set_backlash(path, "X", mm=mm, switch_hysteresis=6.5 / 400)
    path.with_name("machine.toml.bak").unlink()
    (tmp_path / "rig.toml").write_text(sim)
    options = {"free": True, "binary": emulator_binary, "extra_args": ("--machine", str(tmp_path / "rig.toml"))}
    session = Session(Target(emulator=True, emulator_options=options), load_config(path), config_path=path)
    return QuadstepApp(session, poll_interval=0.05), path


def on_screen(screen, selector: str) -> bool:  # noqa: ANN001
    region = screen.query_one(selector).region
    return region.height > 0 and region.bottom <= SIZE[1] and region.right <= SIZE[0]


def shown(screen, selector: str) -> str:  # noqa: ANN001
    """A Static's text as drawn (markup applied)."""
    return str(screen.query_one(selector, Static).render())


async def confirm(pilot, app, answer: str) -> None:  # noqa: ANN001
    await pilot.press("w")
    await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), what="the question")
    await pilot.press(answer)
    await until(pilot, lambda: not isinstance(app.screen, ConfirmScreen), what="the answer")


async def test_the_probe_measures_x_and_the_result_is_written_only_after_yes(tmp_path: Path,
                                                                            emulator_binary: Path) -> None:
    app, path = app_on(tmp_path, emulator_binary, rig_text(0, (37.3, 20.0, 10.0)))
    async with app.run_test(size=SIZE) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")
        await pilot.press("b")
        screen = app.screen
        assert isinstance(screen, BacklashScreen) and on_screen(screen, "#backlash-setup")
        where = "put the probe less than 10 mm outside the target's −X face and less than 3 mm "
        assert where + "inside its −Y edge" in " ".join(shown(screen, "#backlash-setup").split())
        await pilot.press("minus", "minus", "minus")  # 2 tries
        await pilot.press("enter")
        await until(pilot, lambda: screen.result is not None or not screen.running, 60, "the measurement")
        assert screen.result is not None, screen.lines
        assert "X: try 1/2: 37 steps (0.0925 mm)" in screen.lines and "X: try 2/2: 37 steps (0.0925 mm)" in screen.lines
        assert abs(screen.result.steps - 37.3) < 1.0 and screen.result.spread_steps == 0
        assert on_screen(screen, "#backlash-result")
        before = path.read_text()
        await confirm(pilot, app, "n")
        assert path.read_text() == before and not path.with_name("machine.toml.bak").exists()
        await confirm(pilot, app, "y")
        assert load_config(path).axes[0].backlash.mm == round(screen.result.mm, 4)
        drawn = shown(screen, "#backlash-tries") + shown(screen, "#backlash-result")
        assert "[b]" not in drawn and drawn.count("X backlash:") == 1, drawn  # once, as drawn
        assert "wrote X backlash.mm" in drawn, drawn
        assert path.with_name("machine.toml.bak").read_text() == before
        assert app.session.config_given.axes[0].backlash.mm == round(screen.result.mm, 4)  # for the next connection


async def test_a_scattered_switch_result_is_refused_and_cannot_be_written(tmp_path: Path,
                                                                          emulator_binary: Path) -> None:
    sim = rig_text(0, (30.0, 0.0, 0.0)).replace("bounce_ticks = 40\n", "bounce_ticks = 40\njitter = 4\n", 1)
    sim = sim.replace("start = 3800\n", "start = 2400\n", 1)  # 1.5 mm from X's switch, within the 5 mm looked for
    app, path = app_on(tmp_path, emulator_binary, sim)
    async with app.run_test(size=SIZE) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")
        screen = BacklashScreen(app.session, max_spread=0.001)  # a bound the switch's 4-step jitter exceeds
        await app.push_screen(screen)
        await pilot.press("m", "minus", "minus")  # the switch, 3 tries
        assert isinstance(screen, BacklashScreen) and screen.method == "switch"
        await pilot.press("enter")
        await until(pilot, lambda: len(screen.lines) > 1 and not screen.running, 60, "the measurement")
        assert any("refused" in line for line in screen.lines), screen.lines
        assert sum("backlash + hysteresis" in line for line in screen.lines) == 3  # each try as it came
        before = path.read_text()
        await pilot.press("w")
        assert not isinstance(app.screen, ConfirmScreen) and path.read_text() == before


async def test_the_dial_wizard_computes_from_jogs_and_readings(tmp_path: Path, emulator_binary: Path) -> None:
    app, path = app_on(tmp_path, emulator_binary, rig_text(0, (0.0, 0.0, 0.0)), mm=0.0)  # positions: the motor's
    async with app.run_test(size=SIZE) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")
        await pilot.press("b", "d")
        wizard = app.screen
        assert isinstance(wizard, DialWizard) and on_screen(wizard, "#dial-step")
        machine = app.session.machine
        start = machine.position[0]
        await pilot.press("p")  # the preload: 1 mm toward the indicator (the least move)
        await until(pilot, lambda: wizard.stage == "zero" and not wizard.moving, 20, f"the preload {wizard.lines}")
        assert machine.position[0] == start + 400
        await pilot.press("enter")
        assert wizard.stage == "back"
        for key in ("k", "j"):  # 0.01 mm (4 steps) to get close, then one: the needle moves on 5
            await pilot.press(key)
            await until(pilot, lambda: not wizard.moving, 20, "a step back")
        assert machine.position[0] == start + 395
        await pilot.press("enter")
        assert wizard.result is not None and wizard.result.steps == 4 and wizard.result.mm == 0.01
        await pilot.press("p", "enter", "k")  # the needle moves in a large step: refused
        await until(pilot, lambda: wizard.stage == "back" and not wizard.moving, 20, "a large step")
        await pilot.press("enter")
        assert wizard.result is None
        assert "the needle moved during a jog of 4 steps" in wizard.lines[-1], wizard.lines
        await pilot.press("t", "p")  # again, moving back 1 mm and reading the indicator
        await until(pilot, lambda: wizard.stage == "zero" and not wizard.moving, 20, "the preload")
        await pilot.press("enter")
        await until(pilot, lambda: wizard.stage == "moved" and not wizard.moving, 20, "the move back")
        assert on_screen(wizard, "#dial-reading")
        await pilot.press("0", ".", "9", "5", "enter")
        assert abs(wizard.result.mm - 0.05) < 1e-12 and abs(wizard.result.steps - 20) < 1e-9
        before = path.read_text()
        await confirm(pilot, app, "n")
        assert path.read_text() == before
        await confirm(pilot, app, "y")
        assert load_config(path).axes[0].backlash.mm == 0.05


async def test_the_switch_is_calibrated_written_and_then_measures_within_a_step(tmp_path: Path,
                                                                                emulator_binary: Path) -> None:
    backlash = 37.3  # steps; the configuration knows it (as the probe measured it), the switch's 6.5 it does not
    sim = rig_text(0, (backlash, 0.0, 0.0)).replace("start = 3800\n", "start = 2400\n", 1)  # 1.5 mm from the switch
    app, path = app_on(tmp_path, emulator_binary, sim, mm=backlash / 400)
    set_backlash(path, "X", switch_hysteresis=0.03)  # a wrong calibration, to be replaced
    app.session.config_given = load_config(path)
    async with app.run_test(size=SIZE) as pilot:
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")
        await pilot.press("b")
        screen = app.screen
        assert isinstance(screen, BacklashScreen)
        await pilot.press("m")  # the switch: where it must be is said
        assert "X within 5 mm of its homing end's limit switch, off it" in " ".join(
            shown(screen, "#backlash-setup").split())
        await pilot.press("minus", "minus", "minus", "c")  # 2 tries
        await until(pilot, lambda: not screen.running, 60, "the calibration")
        assert screen.calibration is not None, screen.lines
        said = screen.lines[0]  # where the switch must be, and the backlash taken off
        assert "X within 5 mm of it, off it" in said and f"{backlash / 400:.4f} mm" in said, screen.lines
        assert abs(screen.calibration.hysteresis_mm * 400 - 6.5) < 1.0
        assert on_screen(screen, "#backlash-result")
        drawn = shown(screen, "#backlash-tries") + shown(screen, "#backlash-result")
        assert drawn.count("X switch hysteresis:") == 1, drawn  # once
        await confirm(pilot, app, "y")
        written = load_config(path).axes[0].backlash
        assert written.switch_hysteresis == round(screen.calibration.hysteresis_mm, 6)
        assert written.mm == round(backlash / 400, 6)  # the backlash itself kept
        await pilot.press("escape", "ctrl+r")  # the next connection measures with it
        await until(pilot, lambda: app.screen is app.machine, what="the machine screen")
        await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None
                    and app.session.machine.config.axes[0].backlash.switch_hysteresis == written.switch_hysteresis,
                    what="the new connection")
        await pilot.press("b")
        screen = app.screen
        assert isinstance(screen, BacklashScreen)
        await pilot.press("m", "minus", "minus", "minus", "enter")
        await until(pilot, lambda: not screen.running, 60, "the measurement")
        assert screen.result is not None, screen.lines
        assert -1.0 < screen.result.steps - backlash < 1.0, screen.lines
