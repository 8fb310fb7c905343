"""The CUBIC_SEGMENT message: n ticks of jerk-limited motion that carries only what changes
(PROTOCOL.md §5.2).

Per axis, in its direction of motion and in 2^-31 step: the ideal's advance over the next tick
(`speed`), its change per tick (`accel`) and the change of that per tick (`jerk`, the segment's
constant third difference). An axis named with a `speed` is *set* (a corner: new speed, acceleration
and direction); one named with a `jerk` only keeps its state and changes its jerk; one not named
keeps its state with no jerk. The firmware carries the exact state from segment to segment
(docs/CUBIC.md).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from typing import Annotated, Any

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    field_validator,
    model_serializer,
    model_validator,
)

from .constants import CUBIC_ACCEL_LIMIT, CUBIC_N_MAX, CUBIC_SHIFT, MAX_AXES, FieldId
from .segment import Direction, Segment
from .wire import FieldCodec, FieldFault, Int, Request, bits, message

SPEED_BIT = 1 << 31  # in a set's speed word: the axis moves in the negative direction
SET_BYTES = 7  # speed:u32, accel:i24
JERK_BYTES = 2  # jerk:i16


class CubicAxis(BaseModel):
    """One named axis of a cubic segment: a state set (speed, accel, direction), a jerk, or both."""

    model_config = ConfigDict(frozen=True)

    axis: int = Field(ge=0, lt=MAX_AXES)
    speed: int | None = Field(
        default=None, ge=0, lt=1 << 31, description="set: advance over the first tick"
    )
    accel: int = Field(default=0, gt=-CUBIC_ACCEL_LIMIT, lt=CUBIC_ACCEL_LIMIT)
    direction: Direction = 1
    jerk: int | None = Field(default=None, ge=-(1 << 15), lt=1 << 15)

    @model_validator(mode="after")
    def _names_something(self) -> CubicAxis:
        if self.speed is None and (self.accel or self.direction != 1):
            raise ValueError("accel and direction come with a speed (a state set)")
        if self.speed is None and self.jerk is None:
            raise ValueError("an axis named in a cubic segment has a speed, a jerk or both")
        return self

    @property
    def is_set(self) -> bool:
        return self.speed is not None

    @model_serializer(mode="wrap")
    def _only_what_is_named(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields the wire carries for this axis, as protocol/vectors.json writes them."""
        out = handler(self)
        if self.speed is None:
            for key in ("speed", "accel", "direction"):
                out.pop(key, None)
        if self.jerk is None:
            out.pop("jerk", None)
        return out


@dataclass(frozen=True)
class CubicFields(FieldCodec):
    """The `fields` byte (bits 0–3: axes with a jerk, bits 4–7: axes with a state set), then per
    named axis in axis order its set (speed:u32 with the direction in bit 31, accel:i24) and its
    jerk (i16)."""

    head: int = 1
    named_lengths: tuple[tuple[str, int], ...] = (("SET", SET_BYTES), ("JERK", JERK_BYTES))

    def length(self, payload: bytes, offset: int) -> int | None:
        if offset >= len(payload):
            return None
        mask = payload[offset]
        return 1 + SET_BYTES * len(bits(mask >> 4)) + JERK_BYTES * len(bits(mask & 0x0F))

    def pack(self, value: tuple[CubicAxis, ...]) -> bytes:
        mask = 0
        out = bytearray()
        for a in value:
            if a.speed is not None:
                mask |= 16 << a.axis
                out += struct.pack("<I", a.speed | (SPEED_BIT if a.direction < 0 else 0))
                out += (a.accel & 0xFFFFFF).to_bytes(3, "little")
            if a.jerk is not None:
                mask |= 1 << a.axis
                out += struct.pack("<h", a.jerk)
        return bytes([mask]) + bytes(out)

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        """(mask, [(axis, set or None, jerk or None)]) with set = (speed word, accel)."""
        mask = payload[offset]
        at = offset + 1
        items = []
        for axis in range(MAX_AXES):
            set_ = jerk = None
            if mask >> (4 + axis) & 1:
                word = struct.unpack_from("<I", payload, at)[0]
                accel = int.from_bytes(payload[at + 4 : at + 7], "little", signed=True)
                set_ = (word, accel)
                at += SET_BYTES
            if mask >> axis & 1:
                jerk = struct.unpack_from("<h", payload, at)[0]
                at += JERK_BYTES
            if set_ is not None or jerk is not None:
                items.append((axis, set_, jerk))
        return mask, items

    def value(self, raw: Any) -> tuple[CubicAxis, ...]:
        _, items = raw
        axes = []
        for axis, set_, jerk in items:
            if set_ is None:
                axes.append(CubicAxis(axis=axis, jerk=jerk))
            else:
                word, accel = set_
                axes.append(
                    CubicAxis(
                        axis=axis,
                        speed=word & (SPEED_BIT - 1),
                        accel=accel,
                        direction=-1 if word & SPEED_BIT else 1,
                        jerk=jerk,
                    )
                )
        return tuple(axes)


@message(0x12, "CUBIC_SEGMENT")
class CubicSegment(Request):
    """n ticks; axes not listed keep their speed and acceleration, with no jerk."""

    model_config = ConfigDict(frozen=True, extra="ignore")

    n: Annotated[int, Field(ge=1, le=CUBIC_N_MAX), Int("H")]
    axes: Annotated[tuple[CubicAxis, ...], CubicFields()] = ()

    @field_validator("axes")
    @classmethod
    def _ascending_unique(cls, axes: tuple[CubicAxis, ...]) -> tuple[CubicAxis, ...]:
        order = [a.axis for a in axes]
        if order != sorted(set(order)):
            raise ValueError(f"axes must be listed once each in ascending order, got {order}")
        return axes

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The firmware's checks in order: N and AXES, then ACCEL and SPEED against the state each
        axis carries, here that of a freshly started firmware (every axis at rest on the ideal);
        within a chain, cubic_model.CubicChain checks against the state reached."""
        n = raw["n"]
        mask, _ = raw["axes"]
        if n < 1:
            raise FieldFault(FieldId.N, None, f"n = {n}, limit 1..{CUBIC_N_MAX}")
        named = bits((mask | mask >> 4) & 0x0F)
        if any(a >= axis_count for a in named):
            raise FieldFault(FieldId.AXES, None, f"axes {named}, firmware has {axis_count}")
        try:
            CubicChain(axis_count).check(cls.from_wire(raw))
        except CubicRefused as refused:
            raise FieldFault(refused.field, refused.axis, str(refused)) from None


# --- the firmware's chain of cubic state (the model of its validation; cubic_model.py predicts the

SIGMA = 1 << CUBIC_SHIFT
HALF = SIGMA // 2


def choose2(n: int) -> int:
    return n * (n - 1) // 2


def choose3(n: int) -> int:
    return n * (n - 1) * (n - 2) // 6


class CubicRefused(ValueError):
    """A cubic segment the firmware would refuse: the field and axis it names."""

    def __init__(self, field: FieldId, axis: int | None, detail: str) -> None:
        super().__init__(detail)
        self.field = field
        self.axis = axis


@dataclass
class AxisState:
    """One axis of the chain: exact integers (i may be out of range: the next segment is then
    refused)."""

    e: int = 0
    i: int = 0
    d: int = 0
    direction: Direction = 1

    @property
    def at_rest(self) -> bool:
        return self.i == 0 and self.d == 0


def advances_in_range(i: int, d: int, r: int, n: int) -> bool:
    """0 ≤ I(k) ≤ Σ for k = 1..n (the ends, and the extreme where the differences change sign)."""

    def at(k: int) -> int:
        return i + (k - 1) * d + choose2(k - 1) * r

    if not (0 <= i <= SIGMA and 0 <= at(n) <= SIGMA):
        return False
    if r > 0 and d < 0:
        k = 1 + (-d + r - 1) // r
    elif r < 0 and d > 0:
        k = 1 + (d - r - 1) // -r
    else:
        return True
    return k >= n or 0 <= at(k) <= SIGMA


@dataclass
class CubicStep:
    """What one axis does in one segment: its start state, jerk and steps (in its direction)."""

    axis: int
    start: AxisState
    r: int
    steps: int


@dataclass
class CubicChain:
    """The firmware's chain of cubic state, axis by axis."""

    axis_count: int = MAX_AXES
    axes: list[AxisState] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.axes:
            self.axes = [AxisState() for _ in range(self.axis_count)]

    def reset(self) -> None:
        """At rest on the ideal: after STOP, a hold, an alarm."""
        self.axes = [AxisState() for _ in range(self.axis_count)]

    def copy(self) -> CubicChain:
        return CubicChain(
            self.axis_count, [AxisState(a.e, a.i, a.d, a.direction) for a in self.axes]
        )

    def follow_quadratic(self, seg: Segment, totals: dict[int, int]) -> None:
        """The exact end state of a quadratic segment; `totals` its steps per axis."""
        for axis, a in enumerate(self.axes):
            a.d = 0
            mv = next((m for m in seg.axes if m.axis == axis), None)
            if mv is None:
                a.i = 0
                continue
            a.e = (mv.r + seg.n * (mv.v0 + mv.vn) - 8192 * totals[axis]) << 18
            a.i = mv.vn << 19
            a.direction = mv.direction

    def starts(self, seg: CubicSegment) -> list[tuple[AxisState, int]]:
        """Each axis's start state and jerk for `seg` (sets applied), without changing the chain."""
        named = {a.axis: a for a in seg.axes}
        out = []
        for axis, a in enumerate(self.axes):
            start = AxisState(a.e, a.i, a.d, a.direction)
            m = named.get(axis)
            r = 0
            if m is not None:
                if m.speed is not None:
                    if m.direction != a.direction:
                        start.e = -start.e
                    start.direction = m.direction
                    start.i, start.d = m.speed, m.accel
                r = m.jerk or 0
            out.append((start, r))
        return out

    def check(self, seg: CubicSegment) -> None:
        """Raise CubicRefused as the firmware would: AXES, then ACCEL for every axis, then SPEED."""
        named = [a.axis for a in seg.axes]
        if any(a >= self.axis_count for a in named):
            raise CubicRefused(FieldId.AXES, None, f"axes {named}, firmware has {self.axis_count}")
        starts = self.starts(seg)
        n = seg.n
        for axis, (s, r) in enumerate(starts):
            if not (
                -CUBIC_ACCEL_LIMIT < s.d < CUBIC_ACCEL_LIMIT
                and -CUBIC_ACCEL_LIMIT < s.d + n * r < CUBIC_ACCEL_LIMIT
            ):
                raise CubicRefused(
                    FieldId.ACCEL,
                    axis,
                    f"axis {axis}: acceleration {s.d} … {s.d + n * r} leaves 24 bits",
                )
        for axis, (s, r) in enumerate(starts):
            if (s.i or s.d or r) and not advances_in_range(s.i, s.d, r, n):
                raise CubicRefused(
                    FieldId.SPEED, axis, f"axis {axis}: the advance per tick leaves 0 … 1 step"
                )

    def advance(self, seg: CubicSegment) -> list[CubicStep]:
        """Check `seg`, move the chain past it, and return what every moving axis does."""
        self.check(seg)
        n = seg.n
        out = []
        for axis, (s, r) in enumerate(self.starts(seg)):
            a = self.axes[axis]
            a.direction = s.direction
            if s.at_rest and not r:
                a.e, a.i, a.d = s.e, 0, 0
                continue
            travel = n * s.i + choose2(n) * s.d + choose3(n) * r
            total = s.e + travel + HALF
            steps = total >> CUBIC_SHIFT
            a.e = (total & (SIGMA - 1)) - HALF
            a.i = s.i + n * s.d + choose2(n) * r
            a.d = s.d + n * r
            out.append(CubicStep(axis, s, r, steps))
        return out


__all__ = [
    "AxisState",
    "CubicAxis",
    "CubicChain",
    "CubicFields",
    "CubicRefused",
    "CubicSegment",
    "CubicStep",
    "advances_in_range",
]
