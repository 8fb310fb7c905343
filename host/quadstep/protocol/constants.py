"""Every number of the wire protocol (PROTOCOL.md) but the message types and event kinds, which each
message declares itself (wire.py, messages.py). tests/protocol/test_protocol_c_header.py holds these
equal to firmware/core/qs_protocol.h."""

from __future__ import annotations

from enum import IntEnum, IntFlag

# The fixed-point numbers go on the wire as they are: the kernel owns them, the wire names them.
from ..kernel.fixed import (
    CUBIC_ACCEL_LIMIT,
    CUBIC_N_MAX,
    CUBIC_SHIFT,
    DECEL_MAX,
    DECEL_SHIFT,
    MAX_AXES,
    N_MAX,
    R_MAX,
    SPEED_SHIFT,
    V_MAX,
    D,
)

PROTOCOL_VERSION = 3
AXIS_NAMES = ("X", "Y", "Z", "A")  # axis i of every axis mask (PROTOCOL.md §1)
MAX_FRAME = 64  # decoded bytes (body ‖ crc16) per frame
MIN_FRAME = 4  # type, seq, crc16
DELIMITER = 0x00
BROADCAST_SEQ = 0xFF  # seq of unsolicited reports, and of errors about untrusted frames
NO_FIELD = 0  # ERROR field when no field is named
NO_AXIS = 0xFF  # ERROR axis when no axis is named
MAX_IN_FLIGHT = 127  # sequenced frames outstanding at once
# the firmware keeps every step position within ±this (PROTOCOL.md §5.2)
POSITION_MAX = 2**31 - 2**24
WATCHDOG_MAX_MS = 4000  # longest WATCHDOG timeout

__all__ = [
    "AXIS_NAMES",
    "D",
    "MAX_AXES",
    "N_MAX",
    "R_MAX",
    "SPEED_SHIFT",
    "V_MAX",
    "PROTOCOL_VERSION",
    "MAX_FRAME",
    "MIN_FRAME",
    "DELIMITER",
    "BROADCAST_SEQ",
    "NO_FIELD",
    "NO_AXIS",
    "MAX_IN_FLIGHT",
    "DECEL_SHIFT",
    "DECEL_MAX",
    "CUBIC_SHIFT",
    "POSITION_MAX",
    "WATCHDOG_MAX_MS",
    "CUBIC_ACCEL_LIMIT",
    "CUBIC_N_MAX",
    "AckReason",
    "ErrorCode",
    "FieldId",
    "AlarmCode",
    "State",
    "Board",
    "Capability",
    "TypeClass",
    "is_immediate",
    "is_report",
    "is_sequenced",
    "Input",
    "InputCause",
    "INPUT_COUNT",
    "Output",
]


def is_immediate(code: int) -> bool:
    """What the type byte's range says (PROTOCOL.md §3)."""
    return code < 0x10


def is_sequenced(code: int) -> bool:
    return 0x10 <= code < 0x40


def is_report(code: int) -> bool:
    return code >= 0x80


class TypeClass(IntEnum):
    """A message type enum derives from this (messages.py builds it from the declarations)."""

    @property
    def is_immediate(self) -> bool:
        return is_immediate(self)

    @property
    def is_sequenced(self) -> bool:
        return is_sequenced(self)

    @property
    def is_report(self) -> bool:
        return is_report(self)


class AckReason(IntEnum):
    ACCEPTED = 0
    GAP = 1
    DUPLICATE = 2
    QUEUE_FULL = 3
    REJECTED = 4
    SPACE = 5
    PARKED = 6  # after a gap: kept, to run once the frames before it arrive (selective repeat)


class ErrorCode(IntEnum):
    FRAME_TOO_LONG = 1
    FRAME_TOO_SHORT = 2
    BAD_COBS = 3
    BAD_CRC = 4
    UNKNOWN_TYPE = 5
    BAD_LENGTH = 6
    RX_OVERRUN = 7
    BAD_FIELD = 16
    BUSY = 17
    ALARM_ACTIVE = 18
    INPUT_AT_LEVEL = 19


class FieldId(IntEnum):
    N = 1
    AXES = 2
    DIRECTION = 3
    V0 = 4
    VN = 5
    RESIDUAL = 6
    DECEL = 7
    INPUT = 8
    LEVEL = 9
    INPUTS = 10
    HARD_LIMITS = 11
    SPEED = 12
    ACCEL = 13
    POSITION = 14
    TIMEOUT = 15
    OUTPUTS = 16
    REFERENCE = 17
    JERK = 18
    RASTER_AXIS = 19
    PIXELS = 20


class AlarmCode(IntEnum):
    UNDERRUN = 1
    REJECTED_SEGMENT = 2
    HARD_LIMIT = 3
    HOST_LOST = 4
    E_STOP = 5


class State(IntEnum):
    IDLE = 0
    RUNNING = 1
    ALARM = 2
    HOLDING = 3
    STARVED = 4  # at rest after an underrun's stop: motion refused until HOLD or STOP


class Board(IntEnum):
    EMULATOR = 0
    ATMEGA328P = 1
    ATMEGA2560 = 2


class Capability(IntFlag):
    QUADRATIC_SEGMENTS = 1 << 0
    SET_POSITION = 1 << 1
    HOLD = 1 << 2
    JOG = 1 << 3
    LIMIT_INPUTS = 1 << 4
    PROBE_INPUT = 1 << 5
    HOMING = 1 << 6
    CUBIC_SEGMENTS = 1 << 7
    CONTROL_INPUTS = 1 << 8
    CONTROLLED_STOPS = 1 << 9  # an underrun and a silent host end in a hold; WATCHDOG
    OUTPUTS = 1 << 10  # spindle, laser and coolant outputs (OUTPUTS)
    SEGMENTS = 1 << 11  # chained quadratic segments, several to a frame (SEGMENTS)
    CUBIC_RUNS = 1 << 12  # chained cubic segments, several to a frame (CUBIC_SEGMENTS)
    STARVATION_PAUSES = 1 << 13  # an underrun ends in STARVED, not in an alarm
    RASTER = 1 << 14  # laser lines with a power per pixel (RASTER)
    STOPS_ALONG = 1 << 15  # holds along the path (HOLD_ALONG, EVENT HOLD_DONE_ALONG)


class Output(IntFlag):
    """The OUTPUTS bits (PROTOCOL.md §5.5): spindle or laser on, its direction, a power that follows
    an axis's speed, and the coolant outputs."""

    ON = 1 << 0
    REVERSE = 1 << 1
    DYNAMIC = 1 << 2
    MIST = 1 << 4
    FLOOD = 1 << 5


INPUT_COUNT = 12  # inputs the wire names: bit i of every input mask is Input(i)


class Input(IntEnum):
    """The board's inputs (PROTOCOL.md §5.4): an axis's limit (its min switch, or min and max on one
    pin), its max switch where it has a pin of its own, the probe and the control buttons."""

    LIMIT_0 = 0
    LIMIT_1 = 1
    LIMIT_2 = 2
    LIMIT_3 = 3
    LIMIT_MAX_0 = 4
    LIMIT_MAX_1 = 5
    LIMIT_MAX_2 = 6
    LIMIT_MAX_3 = 7
    PROBE = 8
    ABORT = 9
    FEED_HOLD = 10
    CYCLE_START = 11

    @classmethod
    def limit(cls, axis: int, max_end: bool = False) -> Input:
        return cls(axis + (4 if max_end else 0))


class InputCause(IntEnum):
    """What the firmware did when an input's change was accepted (EVENT INPUT)."""

    REPORT = 0
    HARD_LIMIT = 1
    TRIGGER = 2
    E_STOP = 3
    FEED_HOLD = 4
    CYCLE_START = 5
