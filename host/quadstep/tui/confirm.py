"""A yes/no question, and the one way the TUI writes a measured backlash: into the configuration
file after the user confirms (comments kept, the old file kept as FILE.bak;
config_file.set_backlash)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen, Screen
from textual.widgets import Static

from ..config import ConfigError, MachineConfig
from ..config_file import set_backlash


class ConfirmScreen(ModalScreen[bool]):
    """Dismisses with True for y, False for n or Esc."""

    BINDINGS = [Binding("y", "answer(True)", "yes"), Binding("n,escape", "answer(False)", "no")]

    def __init__(self, question: str) -> None:
        super().__init__()
        self.question = question

    def compose(self) -> ComposeResult:
        with Vertical(id="confirm"):
            yield Static(self.question, id="confirm-question")
            yield Static("y: yes   n, Esc: no")

    def action_answer(self, yes: bool) -> None:
        self.dismiss(yes)


def ask_to_write(
    screen: Screen,
    path: Path | None,
    axis: str,
    mm: float,
    say: Callable[[str, bool], None],
    written: Callable[[MachineConfig], None],
    key: str = "mm",
) -> None:
    """Ask, then write `axis`'s backlash.`key` = `mm` to `path` (the backlash itself rounded to
    0.1 µm, as the command writes it); `say(text, error)` reports, `written` gets the configuration
    as now written."""
    if path is None:
        say("no configuration file (--config FILE) to write the backlash to", True)
        return
    what = f"{axis} backlash.{key} = {mm:.4f}"

    def answered(yes: bool | None) -> None:
        if not yes:
            say(f"not written: {what}", False)
            return
        try:
            value = round(mm, 4) if key == "mm" else mm
            config, backup = set_backlash(path, axis, **{key: value})
        except (ConfigError, OSError) as exc:
            say(f"not written: {exc}", True)
            return
        say(
            f"wrote {what} to {path} (the old file is {backup}); it takes effect at the next "
            "connection (Ctrl+R)",
            False,
        )
        written(config)

    screen.app.push_screen(ConfirmScreen(f"Write {what} to {path}?"), answered)
