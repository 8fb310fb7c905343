"""The serial link to a board: a transport (port and threads), a send window with no I/O, the
errors, the HOLD procedure and the inputs' (a motion until an input's edge)."""

from .connection import DEFAULT_BAUD, Link
from .errors import (
    AlarmError,
    BoardReset,
    BoardSilent,
    FirmwareError,
    LinkError,
    LinkTimeout,
    ProtocolVersionError,
    Stopped,
)
from .hold import AlongPath, hold, hold_async, hold_message
from .inputs import input_status, until_input, wait_rest
from .ports import PortError, UsbBoard, auto_port, find_boards
from .stats import LinkStats
from .window import SendWindow

__all__ = [
    "AlarmError",
    "AlongPath",
    "BoardReset",
    "BoardSilent",
    "PortError",
    "UsbBoard",
    "auto_port",
    "find_boards",
    "DEFAULT_BAUD",
    "FirmwareError",
    "Link",
    "LinkError",
    "LinkStats",
    "LinkTimeout",
    "ProtocolVersionError",
    "SendWindow",
    "Stopped",
    "hold",
    "hold_async",
    "hold_message",
    "input_status",
    "until_input",
    "wait_rest",
]
