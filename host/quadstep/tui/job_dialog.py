"""Asks for the job file to show and then run (preview.py), completing the path typed."""

from __future__ import annotations

from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Input, Static

from .preview import PathSuggester


class JobDialog(ModalScreen[Path | None]):
    """Dismisses with the path typed (Enter), or None (Esc)."""

    BINDINGS = [Binding("escape", "cancel", "cancel")]

    def __init__(self, initial: str = "") -> None:
        super().__init__()
        self.initial = initial

    def compose(self) -> ComposeResult:
        with Vertical(id="job-dialog"):
            yield Static("Job file (G-code, or a .json/.yaml move file): → completes the path,")
            yield Static("Enter shows the job (nothing moves yet), Esc cancels:")
            yield Input(
                value=self.initial,
                placeholder="path/to/job.gcode",
                id="job-path",
                suggester=PathSuggester(),
            )

    def on_input_submitted(self, event: Input.Submitted) -> None:
        text = event.value.strip()
        self.dismiss(Path(text).expanduser() if text else None)

    def action_cancel(self) -> None:
        self.dismiss(None)
