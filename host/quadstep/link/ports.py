"""Finding the board: the serial ports whose USB identity is an Arduino Uno or Mega, or a clone's
USB chip.

`--port auto` (and no --port at all) uses the one board found; none or several is an error that
lists what there is. Identities are USB vendor and product ids as pyserial's port listing reports
them.
"""

from __future__ import annotations

from dataclasses import dataclass

from serial.tools import list_ports

# (vendor, product) → what it is
BOARDS = {
    (0x2341, 0x0043): "Arduino Uno",
    (0x2341, 0x0001): "Arduino Uno",
    (0x2341, 0x0243): "Arduino Uno",
    (0x2A03, 0x0043): "Arduino Uno",
    (0x2341, 0x0042): "Arduino Mega 2560",
    (0x2341, 0x0010): "Arduino Mega 2560",
    (0x2341, 0x0242): "Arduino Mega 2560",
    (0x2A03, 0x0042): "Arduino Mega 2560",
    (0x1A86, 0x7523): "CH340 (Uno/Nano/Mega clone)",
    (0x1A86, 0x55D4): "CH9102 (clone)",
    (0x0403, 0x6001): "FTDI FT232 (clone)",
    (0x10C4, 0xEA60): "CP210x (clone)",
}


class PortError(Exception):
    """No board, or more than one, where one was to be found."""


@dataclass(frozen=True)
class UsbBoard:
    """A serial port whose USB identity is a board quadstep runs on."""

    device: str  # /dev/ttyUSB0
    kind: str  # what its USB identity says it is
    serial_number: str | None = None

    def __str__(self) -> str:
        return f"{self.device} ({self.kind})"


def find_boards() -> list[UsbBoard]:
    """Every serial port whose USB identity is a board quadstep runs on, in device order."""
    found = []
    for port in sorted(list_ports.comports(), key=lambda p: p.device):
        kind = BOARDS.get((port.vid, port.pid)) if port.vid is not None else None
        if kind is not None:
            found.append(UsbBoard(port.device, kind, port.serial_number))
    return found


def auto_port(instead: str = "give --port PORT (or --emulator)") -> str:
    """The device of the one board connected; PortError naming what was found otherwise, and what
    the user can do `instead`."""
    boards = find_boards()
    if len(boards) == 1:
        return boards[0].device
    if not boards:
        others = [p.device for p in list_ports.comports()]
        seen = f" (serial ports: {', '.join(others)})" if others else ""
        raise PortError(
            f"no Arduino Uno, Mega or clone found on USB{seen}: plug it in, or {instead}"
        )
    raise PortError(
        f"{len(boards)} boards found ({', '.join(map(str, boards))}): give --port with one of them"
    )
