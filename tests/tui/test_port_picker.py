"""The port picker: pyserial's port listing with the boards named by their USB identity, the one board used
without asking, and the picker when there is not exactly one (here: choosing the emulator)."""

from __future__ import annotations

from pathlib import Path

from serial.tools.list_ports_common import ListPortInfo
from textual.widgets import OptionList

from quadstep.config import MachineConfig
from quadstep.machine import state_path
from quadstep.tui import QuadstepApp, Session, Target
from quadstep.tui.port_picker import EMULATOR, PortPicker, port_choices, the_one_board
from tui_helpers import until


def port(device: str, vid: int | None = None, pid: int | None = None) -> ListPortInfo:
    info = ListPortInfo(device, skip_link_detection=True)
    info.vid, info.pid = vid, pid
    info.description = "USB Serial" if vid is not None else "n/a"
    return info


def test_boards_come_first_named_by_their_usb_identity() -> None:
    choices = port_choices([port("/dev/ttyS0"), port("/dev/ttyUSB0", 0x1A86, 0x7523)])
    assert [(c.device, c.board) for c in choices] == [("/dev/ttyUSB0", "CH340 (Uno/Nano/Mega clone)"), ("/dev/ttyS0", None)]
    one = the_one_board(choices)
    assert one is not None and one.device == "/dev/ttyUSB0"
    two = port_choices([port("/dev/ttyUSB0", 0x1A86, 0x7523), port("/dev/ttyACM0", 0x2341, 0x0043)])
    assert [c.board for c in two] == ["Arduino Uno", "CH340 (Uno/Nano/Mega clone)"]
    assert the_one_board(two) is None  # two boards: the user picks
    assert the_one_board(port_choices([port("/dev/ttyS0")])) is None


async def test_the_picker_lists_the_ports_and_connects_to_the_choice(machine: MachineConfig,
                                                                    emulator_binary: Path) -> None:
    choices = port_choices([port("/dev/ttyS0"), port("/dev/ttyUSB0", 0x1A86, 0x7523),
                            port("/dev/ttyACM0", 0x2341, 0x0042)])
    options = {"free": True, "binary": emulator_binary}

    def choose(device: str) -> Target:
        return Target(emulator=True, emulator_options=options) if device == EMULATOR else Target(port=device)

    session = Session(None, machine, state_file=state_path(None))
    app = QuadstepApp(session, poll_interval=0.05, ports=choices, choose=choose)
    async with app.run_test(size=(80, 24)) as pilot:
        assert isinstance(app.screen, PortPicker)
        listed = app.screen.query_one(OptionList)
        assert [listed.get_option_at_index(i).id for i in range(listed.option_count)] == \
            ["/dev/ttyACM0", "/dev/ttyUSB0", "/dev/ttyS0", EMULATOR]
        assert "Arduino Mega 2560" in str(listed.get_option_at_index(0).prompt)
        box = app.screen.query_one("#port-picker")
        assert box.region.right <= 80 and box.region.bottom <= 24  # fits 80 × 24
        await pilot.press("end", "enter")
        await until(pilot, lambda: session.connected and app.machine.snapshot is not None, what="connection")
        assert session.target is not None and session.target.emulator
        await pilot.press("right")
        await until(pilot, lambda: session.machine is not None and session.machine.status().position[0] == 80,
                    what="a jog")
