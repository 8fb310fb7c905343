"""How a message sits on the wire, declared once, on the message itself.

A message is a pydantic model whose class is declared with `@message(code,
NAME)`; its direction follows from its base (`Request`: host → firmware,
`Report`: firmware → host). Each model field carries its wire form in its
type annotation (`U8`, `U16`, `Positions`, ...: an `Annotated` with a
`FieldCodec` among its metadata), and the fields go on the wire in the order
the model declares them, little-endian. The codec (codec.py) reads nothing
but these declarations, so a new message is one class in one place.

An EVENT is one message type with a kind byte first; each kind is a class of
its own, declared with `@event_kind(code, NAME)` on a subclass of `Event`.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from enum import IntEnum
from typing import Any, ClassVar, TypeVar

from pydantic import BaseModel, ConfigDict

from ..kernel.fixed import MAX_AXES
from .constants import FieldId, TypeClass


class FieldFault(ValueError):
    """A received field the receiver refuses: which field (None: no field id), which axis, why."""

    def __init__(self, field: FieldId | None, axis: int | None, detail: str) -> None:
        super().__init__(detail)
        self.field = field
        self.axis = axis
        self.detail = detail


class FieldCodec:
    """One field's bytes: `head` fixed bytes, then `unit` bytes per repeated item (axes)."""

    @property
    def head(self) -> int:
        return 0

    @property
    def unit(self) -> int:
        return 0

    def length(self, payload: bytes, offset: int) -> int | None:
        """Bytes this field takes at `offset`, or None when the payload cannot hold it."""
        return self.head

    def pack(self, value: Any) -> bytes:
        raise NotImplementedError

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        """The raw value (integers, as on the wire) of the `size` bytes at `offset`."""
        raise NotImplementedError

    def value(self, raw: Any) -> Any:
        """The model's value for a raw value; raises FieldFault for a value the model has no name
        for."""
        return raw


class RecordsField(FieldCodec):
    """Records to the end of the payload (SEGMENTS, CUBIC_SEGMENTS): `parse` reads them all, or says
    None where one is not whole (BAD_LENGTH)."""

    def parse(self, payload: bytes, offset: int) -> tuple[list[Any], int] | None:
        raise NotImplementedError

    def length(self, payload: bytes, offset: int) -> int | None:
        parsed = self.parse(payload, offset)
        return None if parsed is None else parsed[1] - offset

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        parsed = self.parse(payload[: offset + size], offset)
        assert parsed is not None
        return tuple(parsed[0])


@dataclass(frozen=True)
class Int(FieldCodec):
    """A little-endian integer (struct code B H I b h i), or `count` of them; `none` is the wire
    value of None."""

    code: str
    count: int = 1
    enum: type[IntEnum] | None = None
    none: int | None = None

    @property
    def head(self) -> int:
        return struct.calcsize("<" + self.code) * self.count

    def value(self, raw: Any) -> Any:
        if self.none is not None and raw == self.none:
            return None
        if self.enum is not None:
            try:
                return self.enum(raw)
            except ValueError:
                raise FieldFault(None, None, f"unknown {self.enum.__name__} {raw}") from None
        return raw

    @property
    def converts(self) -> bool:
        return self.enum is not None or self.none is not None


@dataclass(frozen=True)
class PerAxis(FieldCodec):
    """The rest of the payload: one integer per axis the firmware has (1 … MAX_AXES of them)."""

    code: str = "i"

    @property
    def unit(self) -> int:
        return struct.calcsize("<" + self.code)

    def length(self, payload: bytes, offset: int) -> int | None:
        rest = len(payload) - offset
        ok = rest % self.unit == 0 and 1 <= rest // self.unit <= MAX_AXES
        return rest if ok else None

    def pack(self, value: Any) -> bytes:
        return struct.pack(f"<{len(value)}{self.code}", *value)

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        return struct.unpack_from(f"<{size // self.unit}{self.code}", payload, offset)


def four_axes(values: Sequence[int]) -> tuple[int, int, int, int]:
    """One value for each of the MAX_AXES (4) axes a field names, as its model takes them."""
    first, second, third, fourth = values
    return first, second, third, fourth


def bits(mask: int) -> list[int]:
    """The set bits of an axis mask, lowest first."""
    return [i for i in range(8) if mask >> i & 1]


@dataclass(frozen=True)
class Masked(FieldCodec):
    """An axis mask byte, then `unit` bytes for each axis it names (`mask_bits` of the mask
    count)."""

    unit_code: str
    mask_bits: int = 0xFF
    head: int = 1

    @property
    def unit(self) -> int:
        return struct.calcsize("<" + self.unit_code)

    def length(self, payload: bytes, offset: int) -> int | None:
        if offset >= len(payload):
            return None
        return self.head + self.unit * len(bits(payload[offset] & self.mask_bits))

    def pack_raw(self, mask: int, flat: list[int]) -> bytes:
        """The mask, then the per-axis values (all of them, in order, as one flat list)."""
        return _repeated(self.unit_code, len(flat) // len(self.unit_code)).pack(mask, *flat)

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        """(mask, [per-axis tuple for each axis in the mask])."""
        mask = payload[offset]
        width = len(self.unit_code)
        flat = _repeated(self.unit_code, len(bits(mask & self.mask_bits))).unpack_from(
            payload, offset
        )[1:]
        return mask, [flat[i : i + width] for i in range(0, len(flat), width)]


@functools.cache
def _repeated(unit_code: str, axes: int) -> struct.Struct:
    """A mask byte and `axes` repeats of `unit_code`."""
    return struct.Struct("<B" + unit_code * axes)


class _IntRun:
    """Consecutive Int fields, packed and unpacked as one struct (the common case, kept fast)."""

    def __init__(self, fields: list[tuple[str, Int]]) -> None:
        self.fields = fields
        self.struct = struct.Struct("<" + "".join(f"{c.count}{c.code}" for _, c in fields))
        self.size = self.struct.size

    def pack(self, message: BaseModel) -> bytes:
        values: list[Any] = []
        for name, c in self.fields:
            v = getattr(message, name)
            if c.count > 1:
                values += v
            else:
                values.append(c.none if v is None else v)
        return self.struct.pack(*values)

    def unpack(self, payload: bytes, offset: int, raw: dict[str, Any]) -> None:
        values = self.struct.unpack_from(payload, offset)
        i = 0
        for name, c in self.fields:
            if c.count > 1:
                raw[name] = values[i : i + c.count]
                i += c.count
            else:
                raw[name] = values[i]
                i += 1


class Layout:
    """A message's payload, compiled once from its declared fields."""

    def __init__(self, prefix: bytes, fields: tuple[tuple[str, FieldCodec], ...]) -> None:
        self.prefix = prefix
        self.fields = fields
        self.parts: list[_IntRun | tuple[str, FieldCodec]] = []
        run: list[tuple[str, Int]] = []
        for name, codec in fields:
            if isinstance(codec, Int):
                run.append((name, codec))
                continue
            if run:
                self.parts.append(_IntRun(run))
                run = []
            self.parts.append((name, codec))
        if run:
            self.parts.append(_IntRun(run))
        self.converters = [(name, c) for name, c in fields if not isinstance(c, Int) or c.converts]

    def pack(self, message: BaseModel) -> bytes:
        out = [self.prefix]
        for part in self.parts:
            if isinstance(part, _IntRun):
                out.append(part.pack(message))
            else:
                out.append(part[1].pack(getattr(message, part[0])))
        return b"".join(out)

    def unpack(self, payload: bytes) -> dict[str, Any] | None:
        """Every field's raw value, or None when the payload's length is wrong."""
        raw: dict[str, Any] = {}
        offset = len(self.prefix)
        end = len(payload)
        for part in self.parts:
            if isinstance(part, _IntRun):
                if offset + part.size > end:
                    return None
                part.unpack(payload, offset, raw)
                offset += part.size
                continue
            name, codec = part
            size = codec.length(payload, offset)
            if size is None or offset + size > end:
                return None
            raw[name] = codec.unpack(payload, offset, size)
            offset += size
        return raw if offset == end else None

    def values(self, raw: dict[str, Any]) -> dict[str, Any]:
        """The model's field values from raw ones; raises FieldFault."""
        values = dict(raw)
        for name, codec in self.converters:
            values[name] = codec.value(raw[name])
        return values


ModelT = TypeVar("ModelT", bound="WireMessage")
_LAYOUTS: dict[type, Layout] = {}


class WireMessage(BaseModel):
    """A protocol message: CODE and NAME from @message, DIRECTION from its base, fields in order."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    CODE: ClassVar[int]
    NAME: ClassVar[str]
    DIRECTION: ClassVar[str]
    TYPE: ClassVar[TypeClass]  # its member of MessageType (set where messages.py builds it)
    KIND: ClassVar[int]  # an EVENT kind's code and name (set by @event_kind)
    KIND_NAME: ClassVar[str]
    PREFIX: ClassVar[bytes] = b""  # bytes before the fields (an EVENT's kind)

    @classmethod
    def layout(cls) -> Layout:
        """The payload's layout, read once from the field annotations."""
        layout = _LAYOUTS.get(cls)
        if layout is None:
            fields = []
            for name, info in cls.model_fields.items():
                codecs = [m for m in info.metadata if isinstance(m, FieldCodec)]
                if len(codecs) != 1:
                    raise TypeError(
                        f"{cls.__name__}.{name} needs exactly one wire form in its annotation"
                    )
                fields.append((name, codecs[0]))
            layout = _LAYOUTS[cls] = Layout(cls.PREFIX, tuple(fields))
        return layout

    @classmethod
    def wire_fields(cls) -> tuple[tuple[str, FieldCodec], ...]:
        """(name, codec) of every model field, in wire order."""
        return cls.layout().fields

    @classmethod
    def wire_head(cls) -> int:
        """Fixed payload bytes (prefix included)."""
        return len(cls.PREFIX) + sum(codec.head for _, codec in cls.wire_fields())

    @classmethod
    def wire_unit(cls) -> int:
        """Bytes per axis of the variable part (0: a fixed-length payload)."""
        return sum(codec.unit for _, codec in cls.wire_fields())

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The receiver's content checks on raw values, in the order of PROTOCOL.md; raise
        FieldFault."""

    @classmethod
    def from_wire(cls: type[ModelT], raw: dict[str, Any]) -> ModelT:
        return cls(**cls.layout().values(raw))


class Request(WireMessage):
    """Host → firmware."""

    DIRECTION = "to_firmware"


class Report(WireMessage):
    """Firmware → host."""

    DIRECTION = "to_host"


@dataclass(frozen=True)
class Declared:
    code: int
    name: str
    cls: type[WireMessage]


_MESSAGES: dict[int, Declared] = {}
_EVENT_KINDS: dict[int, Declared] = {}


def _declare(table: dict[int, Declared], code: int, name: str, cls: type[WireMessage]) -> None:
    for other in table.values():
        if other.code == code or other.name == name:
            raise TypeError(f"{name} = 0x{code:02x} clashes with {other.name} = 0x{other.code:02x}")
    table[code] = Declared(code, name, cls)


def message(code: int, name: str) -> Callable[[type[ModelT]], type[ModelT]]:
    """Declare a message class: its type code (PROTOCOL.md §3 ranges by direction) and wire name."""

    def declare(cls: type[ModelT]) -> type[ModelT]:
        if issubclass(cls, Request) and not 0x01 <= code <= 0x3F:
            raise TypeError(f"{name}: a request's type is 0x01 … 0x3f, not 0x{code:02x}")
        if issubclass(cls, Report) and not 0x80 <= code <= 0xFF:
            raise TypeError(f"{name}: a report's type is 0x80 … 0xff, not 0x{code:02x}")
        cls.CODE, cls.NAME = code, name
        _declare(_MESSAGES, code, name, cls)
        cls.layout()  # every field has its wire form, or the declaration fails here
        return cls

    return declare


def event_kind(code: int, name: str) -> Callable[[type[ModelT]], type[ModelT]]:
    """Declare an EVENT kind: a subclass of Event, the kind byte first on the wire."""

    def declare(cls: type[ModelT]) -> type[ModelT]:
        cls.KIND, cls.KIND_NAME = code, name
        cls.PREFIX = bytes([code])
        _declare(_EVENT_KINDS, code, name, cls)
        cls.layout()  # every field has its wire form, or the declaration fails here
        return cls

    return declare


def declared_messages() -> Iterator[Declared]:
    return iter(sorted(_MESSAGES.values(), key=lambda d: d.code))


def declared_event_kinds() -> Iterator[Declared]:
    return iter(sorted(_EVENT_KINDS.values(), key=lambda d: d.code))


def message_class(code: int) -> type[WireMessage] | None:
    declared = _MESSAGES.get(code)
    return declared.cls if declared is not None else None


def event_class(kind: int) -> type[WireMessage] | None:
    declared = _EVENT_KINDS.get(kind)
    return declared.cls if declared is not None else None
