"""pydantic models of every message (PROTOCOL.md §5), requests and reports.

Enumerated fields accept their name or their number and serialise to the name
in JSON, which is also the form of protocol/vectors.json.
"""

from __future__ import annotations

from enum import IntEnum
from typing import Annotated, ClassVar, Union

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, PlainSerializer

from .constants import (
    DECEL_MAX,
    MAX_AXES,
    AckReason,
    AlarmCode,
    Board,
    Capability,
    ErrorCode,
    EventKind,
    FieldId,
    MessageType,
    State,
)
from .segment import AxisMove, Segment

def _by_name(enum: type[IntEnum]) -> BeforeValidator:
    """Accept an enumerated field by its name as well as by its number."""

    def parse(value: object) -> object:
        if isinstance(value, str):
            try:
                return enum[value]
            except KeyError:
                raise ValueError(f"unknown {enum.__name__} {value!r}") from None
        return value

    return BeforeValidator(parse)


_AS_NAME = PlainSerializer(lambda e: e.name, when_used="json")
NamedAckReason = Annotated[AckReason, _by_name(AckReason), _AS_NAME]
NamedErrorCode = Annotated[ErrorCode, _by_name(ErrorCode), _AS_NAME]
NamedFieldId = Annotated[FieldId, _by_name(FieldId), _AS_NAME]
NamedAlarmCode = Annotated[AlarmCode, _by_name(AlarmCode), _AS_NAME]
NamedState = Annotated[State, _by_name(State), _AS_NAME]
NamedEventKind = Annotated[EventKind, _by_name(EventKind), _AS_NAME]

U8 = Annotated[int, Field(ge=0, le=0xFF)]
U16 = Annotated[int, Field(ge=0, le=0xFFFF)]
U32 = Annotated[int, Field(ge=0, le=0xFFFF_FFFF)]
I32 = Annotated[int, Field(ge=-(2**31), le=2**31 - 1)]
AxisIndex = Annotated[int, Field(ge=0, lt=MAX_AXES)]
Decel = Annotated[int, Field(ge=0, le=DECEL_MAX)]


class _Message(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")
    TYPE: ClassVar[MessageType]


# --- host → firmware ----------------------------------------------------------


class Identify(_Message):
    TYPE = MessageType.IDENTIFY


class Status(_Message):
    TYPE = MessageType.STATUS


class Stop(_Message):
    TYPE = MessageType.STOP


class Hold(_Message):
    """Decelerate every moving axis to rest and drop the queue (PROTOCOL.md §5.1).

    `decel[i]` is axis i's deceleration in 1/2^24 step per tick² (1 … 8191),
    0 for axes the firmware does not have; Link.hold builds it from a list.
    """

    TYPE = MessageType.HOLD
    decel: tuple[Decel, Decel, Decel, Decel]


class SetPosition(_Message):
    """Step positions for the axes listed; only while IDLE with an empty queue."""

    TYPE = MessageType.SET_POSITION
    positions: dict[AxisIndex, I32]


# --- firmware → host ----------------------------------------------------------


class Ack(_Message):
    TYPE = MessageType.ACK
    next_seq: U8
    free: U8
    reason: NamedAckReason
    done: U16


class IdentifyReply(_Message):
    TYPE = MessageType.IDENTIFY_REPLY
    protocol_version: U8
    fw_major: U8
    fw_minor: U8
    fw_patch: U8
    board: U8
    axis_count: U8
    queue_capacity: U8
    speed_shift: U8
    n_max: U16
    tick_hz: U32
    capabilities: U16
    next_seq: U8

    @property
    def firmware_version(self) -> str:
        return f"{self.fw_major}.{self.fw_minor}.{self.fw_patch}"

    @property
    def board_name(self) -> str:
        return Board(self.board).name if self.board in Board._value2member_map_ else f"board {self.board}"

    @property
    def capability_names(self) -> list[str]:
        return [c.name or "" for c in Capability if self.capabilities & c]


class StatusReport(_Message):
    TYPE = MessageType.STATUS_REPORT
    state: NamedState
    alarm: NamedAlarmCode | None
    queue_fill: U8
    next_seq: U8
    segments_done: U32
    motion_ticks: U32
    rx_overrun: U16
    bad_frame: U16
    bad_crc: U16
    seq_gap: U16
    seq_dup: U16
    rejected: U16
    position: tuple[I32, ...] = Field(min_length=1, max_length=MAX_AXES)


class ErrorReport(_Message):
    """ERROR: why the frame (frame_type, frame_seq) was refused."""

    TYPE = MessageType.ERROR
    code: NamedErrorCode
    frame_type: U8
    frame_seq: U8
    field: NamedFieldId | None
    axis: U8 | None

    def describe(self) -> str:
        text = f"{self.code.name} for frame type 0x{self.frame_type:02x} seq {self.frame_seq}"
        if self.field is not None:
            text += f": field {self.field.name}"
        if self.axis is not None:
            text += f" axis {self.axis}"
        return text


class Alarm(_Message):
    TYPE = MessageType.ALARM
    code: NamedAlarmCode
    motion_ticks: U32
    position: tuple[I32, ...] = Field(min_length=1, max_length=MAX_AXES)


class Event(_Message):
    """EVENT; kind HOLD_DONE: a hold began at motion tick `hold_tick` and every axis rests
    at `position` since `motion_ticks`."""

    TYPE = MessageType.EVENT
    kind: NamedEventKind
    hold_tick: U32
    motion_ticks: U32
    position: tuple[I32, ...] = Field(min_length=1, max_length=MAX_AXES)


Request = Union[Identify, Status, Stop, Hold, Segment, SetPosition]
Report = Union[Ack, IdentifyReply, StatusReport, ErrorReport, Alarm, Event]
Message = Union[Request, Report]

MESSAGE_CLASSES: dict[MessageType, type[BaseModel]] = {
    MessageType.IDENTIFY: Identify,
    MessageType.STATUS: Status,
    MessageType.STOP: Stop,
    MessageType.HOLD: Hold,
    MessageType.SEGMENT: Segment,
    MessageType.SET_POSITION: SetPosition,
    MessageType.ACK: Ack,
    MessageType.IDENTIFY_REPLY: IdentifyReply,
    MessageType.STATUS_REPORT: StatusReport,
    MessageType.ERROR: ErrorReport,
    MessageType.ALARM: Alarm,
    MessageType.EVENT: Event,
}


def message_type(message: BaseModel) -> MessageType:
    """The wire type of a message instance."""
    if isinstance(message, Segment):
        return MessageType.SEGMENT
    if isinstance(message, _Message):
        return message.TYPE
    raise TypeError(f"not a protocol message: {type(message).__name__}")


__all__ = [
    "Ack", "Alarm", "AxisMove", "ErrorReport", "Event", "Hold", "Identify", "IdentifyReply", "MESSAGE_CLASSES",
    "Message", "Report", "Request", "Segment", "SetPosition", "Status", "StatusReport", "Stop", "message_type",
]
