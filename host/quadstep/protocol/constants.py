"""Every number of the wire protocol (PROTOCOL.md), in one place."""

from __future__ import annotations

from enum import IntEnum, IntFlag

from .segment import D, MAX_AXES, N_MAX, R_MAX, SPEED_SHIFT

PROTOCOL_VERSION = 1
MAX_FRAME = 64  # decoded bytes (body ‖ crc16) per frame
MIN_FRAME = 4  # type, seq, crc16
DELIMITER = 0x00
BROADCAST_SEQ = 0xFF  # seq of unsolicited reports, and of errors about untrusted frames
MAX_IN_FLIGHT = 127  # sequenced frames outstanding at once
DECEL_SHIFT = 24  # a HOLD deceleration d means d / 2^24 step per tick²
DECEL_MAX = 8191  # largest HOLD deceleration (keeps the hold's per-tick values inside 24 bits)

__all__ = [
    "D", "MAX_AXES", "N_MAX", "R_MAX", "SPEED_SHIFT", "PROTOCOL_VERSION", "MAX_FRAME", "MIN_FRAME",
    "DELIMITER", "BROADCAST_SEQ", "MAX_IN_FLIGHT", "DECEL_SHIFT", "DECEL_MAX", "MessageType", "AckReason",
    "ErrorCode", "FieldId", "AlarmCode", "State", "EventKind", "Board", "Capability",
]


class MessageType(IntEnum):
    IDENTIFY = 0x01
    STATUS = 0x02
    STOP = 0x03
    HOLD = 0x04
    SEGMENT = 0x10
    SET_POSITION = 0x11
    ACK = 0x80
    IDENTIFY_REPLY = 0x81
    STATUS_REPORT = 0x82
    ERROR = 0x83
    ALARM = 0x84
    EVENT = 0x85

    @property
    def is_immediate(self) -> bool:
        return self < 0x10

    @property
    def is_sequenced(self) -> bool:
        return 0x10 <= self < 0x40

    @property
    def is_report(self) -> bool:
        return self >= 0x80


class AckReason(IntEnum):
    ACCEPTED = 0
    GAP = 1
    DUPLICATE = 2
    QUEUE_FULL = 3
    REJECTED = 4
    SPACE = 5


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


class FieldId(IntEnum):
    N = 1
    AXES = 2
    DIRECTION = 3
    V0 = 4
    VN = 5
    RESIDUAL = 6
    DECEL = 7


class AlarmCode(IntEnum):
    UNDERRUN = 1
    REJECTED_SEGMENT = 2
    HARD_LIMIT = 3
    HOST_LOST = 4


class State(IntEnum):
    IDLE = 0
    RUNNING = 1
    ALARM = 2
    HOLDING = 3


class EventKind(IntEnum):
    HOLD_DONE = 1


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
