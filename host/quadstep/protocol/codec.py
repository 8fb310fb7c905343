"""Messages to wire frames and back (PROTOCOL.md §2, §5), driven by the messages' own declarations.

encode(message, seq) gives the bytes to write; Decoder.feed(bytes) gives the
frames received so far, each a Frame or a DecodeError carrying the error code
the firmware would report for it (and field/axis for content errors). Every
layout comes from the message classes (wire.py, messages.py): nothing here
knows any particular message.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ..kernel.fixed import MAX_AXES
from .constants import BROADCAST_SEQ, ErrorCode, FieldId
from .framing import FrameSplitter, FramingError, check_block, encode_frame
from .messages import Event, Message, MessageType
from .wire import FieldFault, WireMessage, event_class, message_class

Direction = Literal["to_host", "to_firmware"]


class DecodeError(Exception):
    """A received frame that is refused, with the code of PROTOCOL.md §6."""

    def __init__(
        self,
        code: ErrorCode,
        frame_type: int = BROADCAST_SEQ,
        frame_seq: int = BROADCAST_SEQ,
        field: FieldId | None = None,
        axis: int | None = None,
        detail: str = "",
    ) -> None:
        self.code = code
        self.frame_type = frame_type
        self.frame_seq = frame_seq
        self.field = field
        self.axis = axis
        self.detail = detail
        super().__init__(self.describe())

    def describe(self) -> str:
        text = self.code.name
        if self.frame_type != BROADCAST_SEQ:
            text += f" (frame type 0x{self.frame_type:02x}, seq {self.frame_seq})"
        if self.field is not None:
            text += f": field {self.field.name}"
            if self.axis is not None:
                text += f" axis {self.axis}"
        if self.detail:
            text += f": {self.detail}"
        return text


@dataclass(frozen=True)
class Frame:
    """One decoded frame: its sequence number and message."""

    seq: int
    message: Message


# --- encoding -----------------------------------------------------------------


def payload(message: Message) -> bytes:
    """The payload bytes of a message (after type and seq)."""
    if not isinstance(message, WireMessage):
        raise TypeError(f"cannot encode {type(message).__name__}")
    return type(message).layout().pack(message)


def encode(message: Message, seq: int) -> bytes:
    """The wire frame of `message` with sequence number `seq`, delimiter included."""
    if not 0 <= seq <= 0xFF:
        raise ValueError(f"seq must be 0..255, got {seq}")
    return encode_frame(bytes([message.CODE, seq]) + payload(message))


# --- decoding -----------------------------------------------------------------


def _message_class(t: int, seq: int, p: bytes, direction: Direction) -> type[WireMessage]:
    cls = message_class(t)
    if cls is None or cls.DIRECTION != direction:
        raise DecodeError(
            ErrorCode.UNKNOWN_TYPE, t, seq, detail=f"type 0x{t:02x} unknown {direction}"
        )
    if cls is Event:  # the kind byte says which
        if not p:
            raise DecodeError(ErrorCode.BAD_LENGTH, t, seq, detail="an EVENT needs its kind")
        kind = event_class(p[0])
        if kind is None:
            raise DecodeError(ErrorCode.BAD_FIELD, t, seq, detail=f"unknown EventKind {p[0]}")
        return kind
    return cls


def decode_body(body: bytes, direction: Direction = "to_host", axis_count: int = MAX_AXES) -> Frame:
    """Decode a checked body (type, seq, payload); raises DecodeError for codes 5–7 and content
    errors.

    `direction` is where the frame travels: the host decodes "to_host"
    frames; "to_firmware" decoding (with the firmware's validation and its
    `axis_count`) serves tests and tools.
    """
    t, seq, p = body[0], body[1], body[2:]
    cls = _message_class(t, seq, p, direction)
    raw = cls.layout().unpack(p)
    if raw is None:
        raise DecodeError(
            ErrorCode.BAD_LENGTH,
            t,
            seq,
            detail=f"{len(p)}-byte payload wrong for {MessageType(t).name}",
        )
    try:
        if direction == "to_firmware":
            cls.check_wire(raw, axis_count)  # the firmware's own validation
        return Frame(seq, cls.from_wire(raw))
    except FieldFault as fault:
        raise DecodeError(
            ErrorCode.BAD_FIELD, t, seq, fault.field, fault.axis, fault.detail
        ) from None


def decode(frame: bytes, direction: Direction = "to_host", axis_count: int = MAX_AXES) -> Frame:
    """Decode one whole wire frame (delimiter optional); raises DecodeError."""
    raw = frame[:-1] if frame.endswith(b"\x00") else frame
    if b"\x00" in raw:
        raise DecodeError(ErrorCode.BAD_COBS, detail="zero byte inside the frame")
    checked = check_block(raw)
    if isinstance(checked, ErrorCode):
        raise DecodeError(checked)
    return decode_body(checked, direction, axis_count)


class Decoder:
    """Streaming decoder: feed any chunks of bytes, get each frame as it completes."""

    def __init__(self, direction: Direction = "to_host", axis_count: int = MAX_AXES) -> None:
        self.direction: Direction = direction
        self.axis_count = axis_count
        self._splitter = FrameSplitter()

    def feed(self, data: bytes) -> list[Frame | DecodeError]:
        out: list[Frame | DecodeError] = []
        for item in self._splitter.feed(data):
            if isinstance(item, FramingError):
                out.append(DecodeError(item.code))
                continue
            try:
                out.append(decode_body(item, self.direction, self.axis_count))
            except DecodeError as error:
                out.append(error)
        return out
