"""The console line (MDI): `:` focuses it, Enter runs the line typed, ↑/↓ go through the lines run
before, Esc gives the keys back to jogging."""

from __future__ import annotations

from typing import Any

from textual.binding import Binding
from textual.message import Message
from textual.widgets import Input

HISTORY = 100  # lines kept


class ConsoleLine(Input):
    BINDINGS = [
        Binding("up", "history(-1)", "earlier", show=False),
        Binding("down", "history(1)", "later", show=False),
        Binding("escape", "leave", "back to jogging", show=False),
    ]

    class Run(Message):
        def __init__(self, text: str) -> None:
            super().__init__()
            self.text = text

    def __init__(self, **kwargs: Any) -> None:  # the Input's own options
        super().__init__(
            placeholder=": G-code line (MDI) — Enter runs it, ↑↓ history, Esc back", **kwargs
        )
        self.history: list[str] = []
        self._at = 0  # index into history while browsing; len(history): the line being typed

    def action_history(self, delta: int) -> None:
        if not self.history:
            return
        self._at = min(max(self._at + delta, 0), len(self.history))
        self.value = self.history[self._at] if self._at < len(self.history) else ""
        self.cursor_position = len(self.value)

    def action_leave(self) -> None:
        self.value = ""
        self.screen.set_focus(None)

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        text = event.value.strip()
        if text:
            if not self.history or self.history[-1] != text:
                self.history = (self.history + [text])[-HISTORY:]
            self.post_message(self.Run(text))
        self.value = ""
        self._at = len(self.history)
