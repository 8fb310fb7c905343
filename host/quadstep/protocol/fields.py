"""The field types messages are declared with: each a type for pydantic and a width on the wire.

`U8`, `U16`, `U32` (and `I32` inside `Positions`), enumerated u8 fields that
take a name or a number and write the name in JSON, the per-axis positions
that fill the rest of a payload, HOLD's four decelerations, an input mask.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Annotated, Any, TypeVar

from pydantic import BeforeValidator, Field, PlainSerializer

from ..kernel.fixed import DECEL_MAX, MAX_AXES
from .constants import (
    INPUT_COUNT,
    NO_AXIS,
    NO_FIELD,
    AckReason,
    AlarmCode,
    ErrorCode,
    FieldId,
    Input,
    InputCause,
    State,
)
from .wire import Int, Masked, PerAxis, bits

E = TypeVar("E", bound=IntEnum)


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


_AS_NAME = PlainSerializer(lambda e: None if e is None else e.name, when_used="json")


def _named(enum: type[E]) -> Any:
    """A u8 field holding one of `enum`'s codes."""
    return Annotated[enum, _by_name(enum), _AS_NAME, Int("B", enum=enum)]


def _named_or_none(enum: type[E], none: int) -> Any:
    """A u8 field holding one of `enum`'s codes, or `none` on the wire for None."""
    return Annotated[enum | None, _by_name(enum), _AS_NAME, Int("B", enum=enum, none=none)]


NamedAckReason = _named(AckReason)
NamedState = _named(State)
NamedErrorCode = _named(ErrorCode)
NamedAlarmCode = _named(AlarmCode)
NamedInput = _named(Input)
NamedCause = _named(InputCause)
OptionalInput = _named_or_none(Input, NO_AXIS)
OptionalAlarmCode = _named_or_none(AlarmCode, 0)
OptionalFieldId = _named_or_none(FieldId, NO_FIELD)

U8 = Annotated[int, Field(ge=0, le=0xFF), Int("B")]
U16 = Annotated[int, Field(ge=0, le=0xFFFF), Int("H")]
U32 = Annotated[int, Field(ge=0, le=0xFFFF_FFFF), Int("I")]
I32 = Annotated[int, Field(ge=-(2**31), le=2**31 - 1)]
AxisIndex = Annotated[int, Field(ge=0, lt=MAX_AXES)]
Decel = Annotated[int, Field(ge=0, le=DECEL_MAX)]
# The step position of every axis the firmware has, to the end of the payload.
Positions = Annotated[tuple[I32, ...], Field(min_length=1, max_length=MAX_AXES), PerAxis("i")]

Decels = Annotated[tuple[Decel, Decel, Decel, Decel], Int("H", count=MAX_AXES)]
InputMask = Annotated[int, Field(ge=0, lt=1 << INPUT_COUNT), Int("H")]


@dataclass(frozen=True)
class PositionsByAxis(Masked):
    """A mask byte, then i32 for each axis in it, in axis order."""

    unit_code: str = "i"

    def pack(self, value: dict[int, int]) -> bytes:
        axes = sorted(value)
        return self.pack_raw(sum(1 << a for a in axes), [value[a] for a in axes])

    def value(self, raw: Any) -> dict[int, int]:
        mask, items = raw
        return {axis: item[0] for axis, item in zip(bits(mask), items)}
