"""Messages to wire frames and back (PROTOCOL.md §2, §5).

encode(message, seq) gives the bytes to write; Decoder.feed(bytes) gives the
frames received so far, each a Frame or a DecodeError carrying the error code
the firmware would report for it (and field/axis for content errors).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum
from typing import Literal, TypeVar

from pydantic import BaseModel

from .constants import (
    BROADCAST_SEQ,
    DECEL_MAX,
    D,
    MAX_AXES,
    N_MAX,
    R_MAX,
    AckReason,
    AlarmCode,
    ErrorCode,
    EventKind,
    FieldId,
    MessageType,
    State,
)
from .framing import FrameSplitter, FramingError, check_block, encode_frame
from .messages import (
    Ack,
    Alarm,
    ErrorReport,
    Event,
    Hold,
    Identify,
    IdentifyReply,
    Message,
    SetPosition,
    Status,
    StatusReport,
    Stop,
    message_type,
)
from .segment import AxisMove, Segment

Direction = Literal["to_host", "to_firmware"]

_IDENTIFY = struct.Struct("<BBBBBBBBHIHB")
_STATUS_HEAD = struct.Struct("<BBBBIIHHHHHH")
_ACK = struct.Struct("<BBBH")
_ERROR = struct.Struct("<BBBBB")
_SEGMENT_HEAD = struct.Struct("<HB")
_SEGMENT_AXIS = struct.Struct("<HHh")
_HOLD = struct.Struct("<4H")
_EVENT_HEAD = struct.Struct("<BII")
_NO_FIELD = 0
_NO_AXIS = 0xFF


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


def _pack_segment(m: Segment) -> bytes:
    mask = 0
    fields = b""
    for a in m.axes:
        mask |= 1 << a.axis
        if a.direction < 0:
            mask |= 1 << (4 + a.axis)
        fields += _SEGMENT_AXIS.pack(a.v0, a.vn, a.r)
    return _SEGMENT_HEAD.pack(m.n, mask) + fields


def _pack_set_position(m: SetPosition) -> bytes:
    axes = sorted(m.positions)
    mask = sum(1 << a for a in axes)
    return bytes([mask]) + struct.pack(f"<{len(axes)}i", *(m.positions[a] for a in axes))


def _pack_status(m: StatusReport) -> bytes:
    head = _STATUS_HEAD.pack(
        m.state, m.alarm or 0, m.queue_fill, m.next_seq, m.segments_done, m.motion_ticks,
        m.rx_overrun, m.bad_frame, m.bad_crc, m.seq_gap, m.seq_dup, m.rejected,
    )
    return head + struct.pack(f"<{len(m.position)}i", *m.position)


def _pack_error(m: ErrorReport) -> bytes:
    field = _NO_FIELD if m.field is None else m.field
    axis = _NO_AXIS if m.axis is None else m.axis
    return _ERROR.pack(m.code, m.frame_type, m.frame_seq, field, axis)


def _pack_alarm(m: Alarm) -> bytes:
    return struct.pack(f"<BI{len(m.position)}i", m.code, m.motion_ticks, *m.position)


def _pack_event(m: Event) -> bytes:
    return _EVENT_HEAD.pack(m.kind, m.hold_tick, m.motion_ticks) + struct.pack(f"<{len(m.position)}i", *m.position)


def _pack_identify_reply(m: IdentifyReply) -> bytes:
    return _IDENTIFY.pack(
        m.protocol_version, m.fw_major, m.fw_minor, m.fw_patch, m.board, m.axis_count, m.queue_capacity,
        m.speed_shift, m.n_max, m.tick_hz, m.capabilities, m.next_seq,
    )


def payload(message: Message) -> bytes:
    """The payload bytes of a message (after type and seq)."""
    if isinstance(message, (Identify, Status, Stop)):
        return b""
    if isinstance(message, Segment):
        return _pack_segment(message)
    if isinstance(message, SetPosition):
        return _pack_set_position(message)
    if isinstance(message, Hold):
        return _HOLD.pack(*message.decel)
    if isinstance(message, Ack):
        return _ACK.pack(message.next_seq, message.free, message.reason, message.done)
    if isinstance(message, IdentifyReply):
        return _pack_identify_reply(message)
    if isinstance(message, StatusReport):
        return _pack_status(message)
    if isinstance(message, ErrorReport):
        return _pack_error(message)
    if isinstance(message, Alarm):
        return _pack_alarm(message)
    if isinstance(message, Event):
        return _pack_event(message)
    raise TypeError(f"cannot encode {type(message).__name__}")


def encode(message: Message, seq: int) -> bytes:
    """The wire frame of `message` with sequence number `seq`, delimiter included."""
    if not 0 <= seq <= 0xFF:
        raise ValueError(f"seq must be 0..255, got {seq}")
    return encode_frame(bytes([message_type(message), seq]) + payload(message))


# --- decoding -----------------------------------------------------------------


def _mask_axes(mask: int) -> list[int]:
    return [i for i in range(8) if mask >> i & 1]


def _bad_field(t: int, seq: int, field: FieldId, axis: int | None, detail: str) -> DecodeError:
    return DecodeError(ErrorCode.BAD_FIELD, t, seq, field, axis, detail)


def _segment_length(p: bytes) -> int | None:
    return 3 + 6 * bin(p[2] & 0x0F).count("1") if len(p) >= 3 else None


def _set_position_length(p: bytes) -> int | None:
    return 1 + 4 * bin(p[0]).count("1") if len(p) >= 1 else None


def _unpack_segment(t: int, seq: int, p: bytes, axis_count: int) -> Segment:
    n, mask = _SEGMENT_HEAD.unpack_from(p)
    if not 1 <= n <= N_MAX:
        raise _bad_field(t, seq, FieldId.N, None, f"n = {n}, limit 1..{N_MAX}")
    active = _mask_axes(mask & 0x0F)
    if any(a >= axis_count for a in active):
        raise _bad_field(t, seq, FieldId.AXES, None, f"axes {active}, firmware has {axis_count}")
    if mask >> 4 & ~mask & 0x0F:
        raise _bad_field(t, seq, FieldId.DIRECTION, None, f"direction bit of an inactive axis (mask 0x{mask:02x})")
    fields = [(axis, *_SEGMENT_AXIS.unpack_from(p, 3 + 6 * j)) for j, axis in enumerate(active)]
    # Field by field as in PROTOCOL.md's table, each field in axis order.
    for axis, v0, _, _ in fields:
        if v0 > D:
            raise _bad_field(t, seq, FieldId.V0, axis, f"v0 = {v0}, limit {D}")
    for axis, _, vn, _ in fields:
        if vn > D:
            raise _bad_field(t, seq, FieldId.VN, axis, f"vn = {vn}, limit {D}")
    for axis, v0, vn, r in fields:
        if not -R_MAX <= r <= R_MAX or (r == R_MAX and v0 == D and vn == D):
            raise _bad_field(t, seq, FieldId.RESIDUAL, axis, f"r = {r} with v0 = {v0}, vn = {vn}")
    moves = [
        AxisMove(axis=axis, direction=-1 if mask >> (4 + axis) & 1 else 1, v0=v0, vn=vn, r=r)
        for axis, v0, vn, r in fields
    ]
    return Segment(n=n, axes=tuple(moves))


def _unpack_set_position(t: int, seq: int, p: bytes, axis_count: int) -> SetPosition:
    axes = _mask_axes(p[0])
    if any(a >= axis_count for a in axes):
        raise _bad_field(t, seq, FieldId.AXES, None, f"axes {axes}, firmware has {axis_count}")
    values = struct.unpack_from(f"<{len(axes)}i", p, 1)
    return SetPosition(positions=dict(zip(axes, values)))


def _unpack_hold(t: int, seq: int, p: bytes, axis_count: int) -> Hold:
    decel = _HOLD.unpack(p)
    # Axis by axis: 1..DECEL_MAX for every axis the firmware has, 0 for the others.
    for axis, d in enumerate(decel):
        if axis < axis_count and not 1 <= d <= DECEL_MAX:
            raise _bad_field(t, seq, FieldId.DECEL, axis, f"decel = {d}, limit 1..{DECEL_MAX}")
        if axis >= axis_count and d != 0:
            raise _bad_field(t, seq, FieldId.DECEL, axis, f"decel = {d} for an axis the firmware lacks ({axis_count} axes)")
    return Hold(decel=decel)


EnumT = TypeVar("EnumT", bound=IntEnum)


def _enum(t: int, seq: int, enum: type[EnumT], value: int) -> EnumT:
    try:
        return enum(value)
    except ValueError:
        raise DecodeError(ErrorCode.BAD_FIELD, t, seq, detail=f"unknown {enum.__name__} {value}") from None


def _unpack_status(t: int, seq: int, p: bytes) -> StatusReport:
    v = _STATUS_HEAD.unpack_from(p)
    axes = (len(p) - _STATUS_HEAD.size) // 4
    return StatusReport(
        state=_enum(t, seq, State, v[0]), alarm=_enum(t, seq, AlarmCode, v[1]) if v[1] else None,
        queue_fill=v[2], next_seq=v[3], segments_done=v[4], motion_ticks=v[5], rx_overrun=v[6],
        bad_frame=v[7], bad_crc=v[8], seq_gap=v[9], seq_dup=v[10], rejected=v[11],
        position=struct.unpack_from(f"<{axes}i", p, _STATUS_HEAD.size),
    )


def _unpack_error(t: int, seq: int, p: bytes) -> ErrorReport:
    code, ftype, fseq, field, axis = _ERROR.unpack(p)
    return ErrorReport(
        code=_enum(t, seq, ErrorCode, code), frame_type=ftype, frame_seq=fseq,
        field=_enum(t, seq, FieldId, field) if field != _NO_FIELD else None,
        axis=None if axis == _NO_AXIS else axis,
    )


def _unpack_alarm(t: int, seq: int, p: bytes) -> Alarm:
    code, ticks = struct.unpack_from("<BI", p)
    axes = (len(p) - 5) // 4
    return Alarm(code=_enum(t, seq, AlarmCode, code), motion_ticks=ticks,
                 position=struct.unpack_from(f"<{axes}i", p, 5))


def _unpack_event(t: int, seq: int, p: bytes) -> Event:
    kind, hold_tick, motion_ticks = _EVENT_HEAD.unpack_from(p)
    axes = (len(p) - _EVENT_HEAD.size) // 4
    return Event(kind=_enum(t, seq, EventKind, kind), hold_tick=hold_tick, motion_ticks=motion_ticks,
                 position=struct.unpack_from(f"<{axes}i", p, _EVENT_HEAD.size))


def _unpack_ack(t: int, seq: int, p: bytes) -> Ack:
    next_seq, free, reason, done = _ACK.unpack(p)
    return Ack(next_seq=next_seq, free=free, reason=_enum(t, seq, AckReason, reason), done=done)


def _unpack_identify_reply(t: int, seq: int, p: bytes) -> IdentifyReply:
    names = ("protocol_version", "fw_major", "fw_minor", "fw_patch", "board", "axis_count", "queue_capacity",
             "speed_shift", "n_max", "tick_hz", "capabilities", "next_seq")
    return IdentifyReply(**dict(zip(names, _IDENTIFY.unpack(p))))


def _fixed(size: int) -> Callable[[bytes], bool]:
    return lambda p: len(p) == size


def _per_axis(head: int) -> Callable[[bytes], bool]:
    return lambda p: len(p) in {head + 4 * k for k in range(1, MAX_AXES + 1)}


def _length_from(expected: Callable[[bytes], int | None]) -> Callable[[bytes], bool]:
    return lambda p: expected(p) == len(p)


# Per direction: type → (length check, unpack(type, seq, payload, axis_count)).
_Unpacker = Callable[[int, int, bytes, int], BaseModel]
_TO_FIRMWARE: dict[int, tuple[Callable[[bytes], bool], _Unpacker]] = {
    MessageType.IDENTIFY: (_fixed(0), lambda t, s, p, k: Identify()),
    MessageType.STATUS: (_fixed(0), lambda t, s, p, k: Status()),
    MessageType.STOP: (_fixed(0), lambda t, s, p, k: Stop()),
    MessageType.HOLD: (_fixed(_HOLD.size), _unpack_hold),
    MessageType.SEGMENT: (_length_from(_segment_length), _unpack_segment),
    MessageType.SET_POSITION: (_length_from(_set_position_length), _unpack_set_position),
}
_TO_HOST: dict[int, tuple[Callable[[bytes], bool], _Unpacker]] = {
    MessageType.ACK: (_fixed(_ACK.size), lambda t, s, p, k: _unpack_ack(t, s, p)),
    MessageType.IDENTIFY_REPLY: (_fixed(_IDENTIFY.size), lambda t, s, p, k: _unpack_identify_reply(t, s, p)),
    MessageType.STATUS_REPORT: (_per_axis(_STATUS_HEAD.size), lambda t, s, p, k: _unpack_status(t, s, p)),
    MessageType.ERROR: (_fixed(_ERROR.size), lambda t, s, p, k: _unpack_error(t, s, p)),
    MessageType.ALARM: (_per_axis(5), lambda t, s, p, k: _unpack_alarm(t, s, p)),
    MessageType.EVENT: (_per_axis(_EVENT_HEAD.size), lambda t, s, p, k: _unpack_event(t, s, p)),
}


def decode_body(body: bytes, direction: Direction = "to_host", axis_count: int = MAX_AXES) -> Frame:
    """Decode a checked body (type, seq, payload); raises DecodeError for codes 5–7 and content errors.

    `direction` is where the frame travels: the host decodes "to_host"
    frames; "to_firmware" decoding (with the firmware's validation and its
    `axis_count`) serves tests and tools.
    """
    t, seq, p = body[0], body[1], body[2:]
    table = _TO_HOST if direction == "to_host" else _TO_FIRMWARE
    if t not in table:
        raise DecodeError(ErrorCode.UNKNOWN_TYPE, t, seq, detail=f"type 0x{t:02x} unknown {direction}")
    length_ok, unpack = table[t]
    if not length_ok(p):
        raise DecodeError(ErrorCode.BAD_LENGTH, t, seq,
                          detail=f"{len(p)}-byte payload wrong for {MessageType(t).name}")
    return Frame(seq, unpack(t, seq, p, axis_count))  # type: ignore[arg-type]


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
