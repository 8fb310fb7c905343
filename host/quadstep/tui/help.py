"""The help screen: every key, and what continuous jogging does on release."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

from ..jog import JogSettings
from ..jog.step_queue import QUEUE_LIMIT
from .keys import HELP


def help_text(settings: JogSettings) -> str:
    return HELP.format(
        steps=min(len(settings.step_presets), 9),
        step_list=" / ".join(f"{s:g}" for s in settings.step_presets),
        speed_list=" / ".join(f"{s * 100:g}" for s in settings.speed_presets),
        first=settings.first_repeat_timeout,
        repeat=settings.repeat_timeout,
        queue=QUEUE_LIMIT,
    )


class HelpScreen(ModalScreen[None]):
    BINDINGS = [
        Binding("escape,q,question_mark,f1", "close", "close"),
    ]

    def __init__(self, settings: JogSettings) -> None:
        super().__init__()
        self.settings = settings

    def compose(self) -> ComposeResult:
        with VerticalScroll(id="help"):
            yield Static(help_text(self.settings))

    def on_mount(self) -> None:
        box = self.query_one("#help")
        box.border_title = "help: ↑ ↓ PgUp PgDn scroll, Esc closes"
        box.focus()  # the arrow and page keys scroll it

    def action_close(self) -> None:
        self.dismiss(None)
