"""Every message of PROTOCOL.md §5, each declared once: type code, name, direction, fields and
widths.

A message is a class declared with `@message(code, NAME)` on `Request` (host
→ firmware) or `Report` (firmware → host); its fields go on the wire in the
order written here, each as its annotation says (U8, U16, I32, Positions,
...: fields.py). An EVENT kind is a subclass of `Event` declared with `@event_kind`.
`MessageType` and `EventKind` are built from these declarations.

Enumerated fields accept their name or their number and serialise to the name
in JSON, which is also the form of protocol/vectors.json.
"""

from __future__ import annotations

from enum import EnumMeta, IntEnum
from typing import Annotated, Any, ClassVar, TypeVar

from pydantic import (
    Field,
    SerializationInfo,
    SerializerFunctionWrapHandler,
    model_serializer,
    model_validator,
)

from ..kernel.fixed import DECEL_MAX
from ..kernel.motion import AxisMove, CubicAxis
from .constants import (
    INPUT_COUNT,
    NO_AXIS,
    POSITION_MAX,
    WATCHDOG_MAX_MS,
    Board,
    Capability,
    FieldId,
    Input,
    TypeClass,
)
from .cubic import CubicSegment
from .cubic_run import CubicRecord, CubicSegments
from .fields import (
    I32,
    U8,
    U16,
    U32,
    AxisIndex,
    Decels,
    NamedAckReason,
    NamedAlarmCode,
    NamedCause,
    NamedErrorCode,
    NamedInput,
    NamedState,
    OptionalAlarmCode,
    OptionalFieldId,
    OptionalInput,
    Positions,
    PositionsByAxis,
)
from .outputs import Outputs
from .raster import Raster
from .segment import Segment
from .segment_run import SegmentRecord, Segments
from .wire import (
    FieldFault,
    Int,
    Report,
    Request,
    WireMessage,
    bits,
    declared_event_kinds,
    declared_messages,
    event_kind,
    message,
)

# --- host → firmware ----------------------------------------------------------


@message(0x01, "IDENTIFY")
class Identify(Request):
    pass


@message(0x02, "STATUS")
class Status(Request):
    pass


@message(0x03, "STOP")
class Stop(Request):
    pass


@message(0x04, "HOLD")
class Hold(Request):
    """Decelerate every moving axis to rest and drop the queue (PROTOCOL.md §5.1).

    `decel[i]` is axis i's deceleration in 1/2^24 step per tick² (1 … 8191),
    0 for axes the firmware does not have; Link.hold builds it from a list.
    """

    decel: Decels

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """Axis by axis: 1..DECEL_MAX for every axis the firmware has, 0 for the others."""
        _check_decel(raw["decel"], axis_count)


@message(0x08, "HOLD_ALONG")
class HoldAlong(Request):
    """A HOLD that stops along the path (PROTOCOL.md §5.1): where the hold begins in a segment whose
    done count (segments_done mod 2^16 while it runs) lies in `first` … `last`, the board takes
    `path_decel`, decelerations in proportion to those segments' speeds on each axis, so that the
    axes stop together on their line; elsewhere `decel`, as HOLD. Its HOLD_DONE says which
    (HoldDoneAlong for `path_decel`)."""

    decel: Decels
    path_decel: Decels
    first: U16
    last: U16

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """Both sets of decelerations by HOLD's rule, the HOLD's first."""
        _check_decel(raw["decel"], axis_count)
        _check_decel(raw["path_decel"], axis_count)


def _check_decel(values: Any, axis_count: int) -> None:
    """HOLD's rule: 1..DECEL_MAX for every axis the firmware has, 0 for the others, axis by axis."""
    for axis, d in enumerate(values):
        if axis < axis_count and not 1 <= d <= DECEL_MAX:
            raise FieldFault(FieldId.DECEL, axis, f"decel = {d}, limit 1..{DECEL_MAX}")
        if axis >= axis_count and d != 0:
            raise FieldFault(
                FieldId.DECEL,
                axis,
                f"decel = {d} for an axis the firmware lacks ({axis_count} axes)",
            )


@message(0x06, "INPUTS")
class Inputs(Request):
    """The inputs' state and settings now (answered by INPUT_STATUS)."""


@message(0x07, "WATCHDOG")
class Watchdog(Request):
    """Stop (a hold at CONFIG's hold_decel, then ALARM HOST_LOST) when no good frame has come for
    `timeout_ms` while moving; 0 turns it off (PROTOCOL.md §5.1). Answered by STATUS_REPORT."""

    timeout_ms: U16

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        if raw["timeout_ms"] > WATCHDOG_MAX_MS:
            raise FieldFault(
                FieldId.TIMEOUT,
                None,
                f"timeout_ms = {raw['timeout_ms']}, limit 0..{WATCHDOG_MAX_MS}",
            )


@message(0x11, "SET_POSITION")
class SetPosition(Request):
    """Step positions for the axes listed; only while IDLE with an empty queue."""

    positions: Annotated[dict[AxisIndex, I32], PositionsByAxis()]

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        mask, items = raw["positions"]
        axes = bits(mask)
        if any(a >= axis_count for a in axes):
            raise FieldFault(FieldId.AXES, None, f"axes {axes}, firmware has {axis_count}")
        for axis, item in zip(axes, items):
            if abs(item[0]) > POSITION_MAX:
                raise FieldFault(
                    FieldId.POSITION, axis, f"position = {item[0]}, limit ±{POSITION_MAX}"
                )


@message(0x15, "PROBE")
class Probe(Request):
    """The motion that follows ends where `input` reaches `level` (1 active, 0 inactive): at that
    tick the firmware latches every position (EVENT INPUT, cause TRIGGER) and holds at `decel`
    (HOLD's units; HOLD_DONE follows). If the motion comes to rest first: EVENT PROBE_MISSED. Only
    while IDLE with nothing queued."""

    input: NamedInput
    level: U8
    decel: Decels

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        if raw["input"] > Input.PROBE:
            raise FieldFault(
                FieldId.INPUT,
                None,
                f"input {raw['input']}: only a limit or the probe can end a motion",
            )
        if raw["level"] > 1:
            raise FieldFault(FieldId.LEVEL, None, f"level = {raw['level']}, limit 0..1")
        _check_decel(raw["decel"], axis_count)


@message(0x16, "CONFIG")
class Config(Request):
    """The inputs' settings: polarity (bit set: active high), which are acted on, hard limits on or
    off, each input's debounce in ticks, and the feed hold input's decelerations (HOLD's units). Not
    while moving."""

    invert: U16
    enabled: U16
    hard_limits: U8
    debounce: Annotated[
        tuple[U8, ...],
        Field(min_length=INPUT_COUNT, max_length=INPUT_COUNT),
        Int("B", count=INPUT_COUNT),
    ]
    hold_decel: Decels

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        if (raw["invert"] | raw["enabled"]) >> INPUT_COUNT:
            raise FieldFault(FieldId.INPUTS, None, f"input bits above {INPUT_COUNT - 1}")
        if raw["hard_limits"] > 1:
            raise FieldFault(
                FieldId.HARD_LIMITS, None, f"hard_limits = {raw['hard_limits']}, limit 0..1"
            )
        _check_decel(raw["hold_decel"], axis_count)


# --- firmware → host ----------------------------------------------------------


@message(0x80, "ACK")
class Ack(Report):
    next_seq: U8
    free: U8
    reason: NamedAckReason
    done: U16


@message(0x81, "IDENTIFY_REPLY")
class IdentifyReply(Report):
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
    boot_id: U16  # new at each reset: a board reset since (its positions lost) shows another
    raster_ring: U16 = 0  # pixel powers RASTER lines may hold queued on the board; 0 without RASTER

    @property
    def firmware_version(self) -> str:
        return f"{self.fw_major}.{self.fw_minor}.{self.fw_patch}"

    @property
    def board_name(self) -> str:
        return (
            Board(self.board).name
            if self.board in Board._value2member_map_
            else f"board {self.board}"
        )

    @property
    def capability_names(self) -> list[str]:
        return [c.name or "" for c in Capability if self.capabilities & c]


@message(0x82, "STATUS_REPORT")
class StatusReport(Report):
    state: NamedState
    alarm: OptionalAlarmCode
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
    position: Positions


@message(0x83, "ERROR")
class ErrorReport(Report):
    """ERROR: why the frame (frame_type, frame_seq) was refused."""

    code: NamedErrorCode
    frame_type: U8
    frame_seq: U8
    field: OptionalFieldId
    axis: Annotated[U8 | None, Int("B", none=NO_AXIS)]

    def describe(self) -> str:
        text = f"{self.code.name} for frame type 0x{self.frame_type:02x} seq {self.frame_seq}"
        if self.field is not None:
            text += f": field {self.field.name}"
        if self.axis is not None:
            text += f" axis {self.axis}"
        return text


@message(0x84, "ALARM")
class Alarm(Report):
    code: NamedAlarmCode
    motion_ticks: U32
    position: Positions


@message(0x85, "EVENT")
class Event(Report):
    """EVENT: something no request asked about. One subclass per kind (@event_kind), whose kind byte
    comes first on the wire; `kind` is read and written by name like an enumerated field."""

    KIND: ClassVar[int]
    KIND_NAME: ClassVar[str]

    @property
    def kind(self) -> IntEnum:
        return EventKind(self.KIND)

    @model_validator(mode="before")
    @classmethod
    def _kind_names_this_class(cls, data: Any) -> Any:
        if isinstance(data, dict) and "kind" in data:
            data = dict(data)
            kind = data.pop("kind")
            if kind not in (cls.KIND, cls.KIND_NAME):
                raise ValueError(f"kind {kind!r} is not {cls.KIND_NAME}")
        return data

    @model_serializer(mode="wrap")
    def _with_kind(
        self, handler: SerializerFunctionWrapHandler, info: SerializationInfo
    ) -> dict[str, Any]:
        return {"kind": self.KIND_NAME if info.mode == "json" else self.kind, **handler(self)}


@event_kind(1, "HOLD_DONE")
class HoldDone(Event):
    """A hold began at motion tick `hold_tick`; every axis rests at `position` since
    `motion_ticks`."""

    hold_tick: U32
    motion_ticks: U32
    position: Positions


@event_kind(4, "HOLD_DONE_ALONG")
class HoldDoneAlong(HoldDone):
    """HOLD_DONE of a hold begun with a HOLD_ALONG's path decelerations."""


@message(0x86, "INPUT_STATUS")
class InputStatus(Report):
    """The inputs now: which the firmware has, which are active, the raw pin levels (bit set: high),
    the settings, the armed PROBE's input and level (None: nothing armed) and latches lost to a full
    ring."""

    present: U16
    active: U16
    raw: U16
    invert: U16
    enabled: U16
    hard_limits: U8
    armed: OptionalInput
    level: U8
    latches_lost: U16

    def is_active(self, which: Input) -> bool:
        return bool(self.active >> which & 1)


@event_kind(2, "INPUT")
class InputChange(Event):
    """An input's accepted change: at motion tick `motion_ticks` every axis was at `position`
    (exact: the latch of the tick of its first edge); `active` the inputs active after it, `changed`
    those that changed, `cause` what the firmware did."""

    motion_ticks: U32
    active: U16
    changed: U16
    cause: NamedCause
    position: Positions

    def became_active(self, which: Input) -> bool:
        return bool(self.changed >> which & 1 and self.active >> which & 1)


@event_kind(3, "PROBE_MISSED")
class ProbeMissed(Event):
    """The motion after a PROBE came to rest at `position` (motion tick `motion_ticks`) without the
    edge."""

    motion_ticks: U32
    position: Positions


# --- built from the declarations above ------------------------------------------

_E = TypeVar("_E", bound=IntEnum)


def _enum(base: type[_E], name: str, members: list[tuple[str, int]]) -> type[_E]:
    """An enum derived from `base` with members made at import: the functional API, spelled as the
    metaclass call it is, which a type checker can follow."""
    made = EnumMeta.__call__(base, name, members, module=__name__)
    assert issubclass(made, base)
    return made


MessageType = _enum(TypeClass, "MessageType", [(d.name, d.code) for d in declared_messages()])
EventKind = _enum(IntEnum, "EventKind", [(d.name, d.code) for d in declared_event_kinds()])
for _declared in declared_messages():
    _declared.cls.TYPE = MessageType(_declared.code)

Message = WireMessage


def message_type(message: WireMessage) -> Any:
    """The wire type of a message instance."""
    if isinstance(message, WireMessage):
        return MessageType(message.CODE)
    raise TypeError(f"not a protocol message: {type(message).__name__}")


def queue_slots(message: WireMessage) -> int:
    """Queue slots the firmware gives a sequenced message: one a segment, one a record of SEGMENTS
    and CUBIC_SEGMENTS."""
    if isinstance(message, (Segments, CubicSegments)):
        return len(message.records)
    return 1 if isinstance(message, (Segment, CubicSegment, Raster)) else 0


def message_from_json(fields: dict[str, Any]) -> tuple[int, WireMessage]:
    """(seq, message) from the JSON form of vectors.json: {"type": NAME, "seq": n, ...fields}."""
    data = dict(fields)
    declared = next((d for d in declared_messages() if d.name == data.get("type")), None)
    if declared is None:
        raise ValueError(f"unknown message type {data.get('type')!r}")
    del data["type"]
    seq = data.pop("seq")
    cls = declared.cls
    if cls is Event:
        kind = next((k.cls for k in declared_event_kinds() if k.name == data.get("kind")), None)
        if kind is None:
            raise ValueError(f"unknown EVENT kind {data.get('kind')!r}")
        cls = kind
    return seq, cls.model_validate(data)


__all__ = [
    "Ack",
    "Alarm",
    "AxisMove",
    "Config",
    "CubicAxis",
    "CubicSegment",
    "ErrorReport",
    "Event",
    "EventKind",
    "Hold",
    "HoldAlong",
    "HoldDone",
    "HoldDoneAlong",
    "Identify",
    "IdentifyReply",
    "InputChange",
    "InputStatus",
    "Inputs",
    "Message",
    "MessageType",
    "Outputs",
    "Probe",
    "ProbeMissed",
    "Raster",
    "CubicRecord",
    "CubicSegments",
    "Report",
    "Request",
    "Segment",
    "SegmentRecord",
    "Segments",
    "SetPosition",
    "Status",
    "StatusReport",
    "Stop",
    "message_from_json",
    "message_type",
    "queue_slots",
]
