"""Which board to talk to, when `quadstep tui` is given no --port and not exactly one board is
plugged in: the serial ports pyserial lists (boards first, named by their USB identity), and the
emulator."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from serial.tools import list_ports
from serial.tools.list_ports_common import ListPortInfo
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import OptionList, Static
from textual.widgets.option_list import Option

from ..link.ports import BOARDS

EMULATOR = "emulator"


@dataclass(frozen=True)
class PortChoice:
    device: str
    board: str | None  # what its USB identity says it is; None: not a known board
    description: str


def port_choices(ports: Sequence[ListPortInfo] | None = None) -> list[PortChoice]:
    """The serial ports (pyserial's listing unless given), the known boards first."""
    found = []
    for port in list_ports.comports() if ports is None else ports:
        board = BOARDS.get((port.vid, port.pid)) if port.vid is not None else None
        found.append(PortChoice(port.device, board, port.description or "n/a"))
    return sorted(found, key=lambda c: (c.board is None, c.device))


def the_one_board(choices: Sequence[PortChoice]) -> PortChoice | None:
    """The board to use without asking: exactly one known board is plugged in."""
    boards = [c for c in choices if c.board is not None]
    return boards[0] if len(boards) == 1 else None


class PortPicker(ModalScreen[str]):
    """Dismisses with the device chosen, or EMULATOR."""

    BINDINGS = [Binding("escape", "emulator", "the emulator")]

    def __init__(self, choices: Sequence[PortChoice]) -> None:
        super().__init__()
        self.choices = list(choices)

    def compose(self) -> ComposeResult:
        boards = sum(c.board is not None for c in self.choices)
        heading = (
            "No board found by its USB identity" if boards == 0 else f"{boards} boards found"
        ) + ": pick the port (↑ ↓, Enter), or the emulator (Esc)."
        options = [
            Option(f"{c.device:<16} {c.board or '—':<24} {c.description}"[:74], id=c.device)
            for c in self.choices
        ]
        options.append(
            Option("the emulator (no board: the firmware core on this computer)", id=EMULATOR)
        )
        with Vertical(id="port-picker"):
            yield Static(heading)
            yield OptionList(*options, id="ports")

    def on_mount(self) -> None:
        self.query_one(OptionList).focus()

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        self.dismiss(event.option.id or EMULATOR)

    def action_emulator(self) -> None:
        self.dismiss(EMULATOR)
