"""The help screen: every key, and what continuous jogging does on release."""

from __future__ import annotations

from collections.abc import Sequence

from rich.markup import escape
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

from ..jog import JogSettings
from ..jog.step_queue import QUEUE_LIMIT
from ..macro_settings import Macro
from .keys import HELP


def help_text(settings: JogSettings, macros: Sequence[Macro] = ()) -> str:
    return _macro_help(macros) + HELP.format(
        steps=min(len(settings.step_presets), 9),
        step_list=" / ".join(f"{s:g}" for s in settings.step_presets),
        speed_list=" / ".join(f"{s * 100:g}" for s in settings.speed_presets),
        first=settings.first_repeat_timeout,
        repeat=settings.repeat_timeout,
        queue=QUEUE_LIMIT,
    )


def _macro_help(macros: Sequence[Macro]) -> str:
    """The configuration's macros, first: they are this machine's own keys."""
    if not macros:
        return ""
    lines = ["[b]Macros[/b] (the configuration's \\[\\[macros]])"]
    for macro in macros:
        lines.append(f"  {macro.key:<14} {escape(macro.name)}")
        lines += [f"{'':17}{escape(line)}" for line in macro.gcode]
    return "\n".join(lines) + "\n\n"


class HelpScreen(ModalScreen[None]):
    BINDINGS = [
        Binding("escape,q,question_mark,f1", "close", "close"),
    ]

    def __init__(self, settings: JogSettings, macros: Sequence[Macro] = ()) -> None:
        super().__init__()
        self.settings = settings
        self.macros = macros

    def compose(self) -> ComposeResult:
        with VerticalScroll(id="help"):
            yield Static(help_text(self.settings, self.macros))

    def on_mount(self) -> None:
        box = self.query_one("#help")
        box.border_title = "help: ↑ ↓ PgUp PgDn scroll, Esc closes"
        box.focus()  # the arrow and page keys scroll it

    def action_close(self) -> None:
        self.dismiss(None)
