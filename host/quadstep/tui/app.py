"""`quadstep tui`: the Textual application around one Session and its machine screen."""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Sequence

from textual.app import App
from textual.binding import Binding

from ..machine import Target
from .kitty import KeyboardFlags, KeyRelease, ReleaseDriver
from .port_picker import EMULATOR, PortChoice, PortPicker, port_choices
from .screen import MachineScreen
from .session import Session


class QuadstepApp(App[None]):
    CSS_PATH = "quadstep.tcss"  # packaged with it (pyproject package-data)
    ENABLE_COMMAND_PALETTE = False
    BINDINGS = [Binding("ctrl+c", "interrupt", "stop and quit", show=False, priority=True)]
    interrupted = False  # Ctrl-C ended it: `quadstep tui` exits 130, as the other commands do

    def __init__(
        self,
        session: Session,
        job_path: str = "",
        poll_interval: float | None = None,
        ports: Sequence[PortChoice] | None = None,
        choose: Callable[[str], Target] | None = None,
    ) -> None:
        """Without a target in `session`, the port picker comes first: `ports` (default: pyserial's
        listing), and `choose` makes the Target of the device picked (or EMULATOR)."""
        super().__init__(driver_class=ReleaseDriver)
        self.session = session
        self.ports = ports
        self.choose = choose or _target
        if poll_interval is None:
            self.machine = MachineScreen(session, job_path)
        else:
            self.machine = MachineScreen(session, job_path, poll_interval)

    def on_mount(self) -> None:
        if self.session.target is None:
            ports = list(self.ports) if self.ports is not None else port_choices()
            self.push_screen(PortPicker(ports), self._port_chosen)
        else:
            self.push_screen(self.machine)

    def _port_chosen(self, device: str | None) -> None:
        self.session.target = self.choose(device or EMULATOR)
        self.push_screen(self.machine)

    def on_key_release(self, message: KeyRelease) -> None:
        self.machine.key_released(message.key)

    def on_keyboard_flags(self, message: KeyboardFlags) -> None:
        if message.releases:
            self.session.releases_reported()
            self.machine.refresh_panels()
            self.machine.log_line(
                "the terminal reports key releases (kitty keyboard protocol): a continuous jog "
                "stops when its key is let go"
            )

    def action_interrupt(self) -> None:
        """Ctrl-C: as Ctrl+Q, any motion brought to rest with HOLD first (on_unmount); the command
        prints where."""
        self.interrupted = True
        self.exit()

    async def on_unmount(self) -> None:
        await asyncio.to_thread(self._shut_down)

    def _shut_down(self) -> None:
        self.session.close()  # brings a running jog or job to rest (HOLD) before the link closes


def _target(device: str) -> Target:
    return Target(emulator=True) if device == EMULATOR else Target(port=device)
