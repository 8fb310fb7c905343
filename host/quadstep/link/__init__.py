"""The serial link to a board: a transport (port and threads), a send window with no I/O, the errors,
and the HOLD procedure."""

from .connection import DEFAULT_BAUD, Link
from .errors import AlarmError, FirmwareError, LinkError, LinkTimeout, ProtocolVersionError, Stopped
from .hold import hold, hold_async, hold_message
from .stats import LinkStats
from .window import SendWindow

__all__ = [
    "AlarmError", "DEFAULT_BAUD", "FirmwareError", "Link", "LinkError", "LinkStats", "LinkTimeout",
    "ProtocolVersionError", "SendWindow", "Stopped", "hold", "hold_async", "hold_message",
]
