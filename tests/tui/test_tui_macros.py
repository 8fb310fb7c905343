"""[[macros]] in the configuration: checked at load (a bad G-code line named with its macro and
line, a key the TUI uses, nothing starts), listed in the help, and run through the machine as typed
lines are, the console's modal state carried into and out of them."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.cli import main
from quadstep.config import MachineConfig, parse_config
from quadstep.tui.help import HelpScreen, help_text
from test_tui import connected, make_app, shown
from tui_helpers import MACHINE, log_text, until
from tui_layout import assert_nothing_cut

MACROS = [
    {"key": "f5", "name": "out and over", "gcode": ["G91 G1 X5 F600", "Y2.5"]},
    {"key": "m", "name": "to work zero", "gcode": ["G90 G0 X0 Y0"]},
]


def with_macros(macros: list[dict[str, object]]) -> MachineConfig:
    return parse_config({**MACHINE, "macros": macros}, "test machine")


async def test_macros_run_like_typed_lines_and_are_in_the_help(emulator_binary: Path) -> None:
    app = make_app(with_macros(MACROS), emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("f5")
        await until(pilot, lambda: "out and over: done" in log_text(app), what="the macro")
        await shown(pilot, app, (400, 200, 0))
        # G91, G1 and F600 carry over to a typed line, as from one typed line to the next
        await pilot.press("colon", "X", "1", "enter", "escape")
        await until(pilot, lambda: "MDI: done" in log_text(app), what="the line")
        await shown(pilot, app, (480, 200, 0))
        await pilot.press("m")
        await until(pilot, lambda: "to work zero: done" in log_text(app), what="the second macro")
        await shown(pilot, app, (0, 0, 0))
        assert "macro out and over: G91 G1 X5 F600 | Y2.5" in log_text(app)
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        text = help_text(app.session.settings, app.machine.macros)
        assert "  f5             out and over\n                 G91 G1 X5 F600\n" in text
        assert_nothing_cut(app)


@pytest.mark.parametrize(
    ("macros", "said"),
    [
        ([{"key": "f6", "name": "bad", "gcode": ["G0 X1", "G1 Q3 X2"]}],
         "macros[0] (bad) line 2: column 4: 'Q3' is only used with G64"),
        ([{"key": "x", "name": "mine", "gcode": ["G0 X1"]}],
         "macros[0] (mine): key 'x' is the TUI's own"),
        ([{"key": "f5", "name": "a", "gcode": ["G0 X1"]}, {"key": "F5", "name": "b", "gcode": ["G0 X2"]}],
         "macros[1] (b): key 'f5' is a's already"),
    ],
)
def test_a_bad_macro_is_refused_at_load(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], macros: list[dict[str, object]], said: str
) -> None:
    import tomlkit

    config = tmp_path / "machine.toml"
    config.write_text(tomlkit.dumps({**MACHINE, "macros": macros}))
    assert main(["tui", "--emulator", "--config", str(config)]) == 1
    assert f"{config}: {said}" in capsys.readouterr().err


def test_a_macro_key_must_be_a_key() -> None:
    with pytest.raises(ValueError, match="key = '!': must be a letter, a digit or F2 … F12"):
        with_macros([{"key": "!", "name": "bang", "gcode": ["G0 X1"]}])
