"""The CUBIC_SEGMENTS message: chained cubic segments, several to a frame (PROTOCOL.md §5.2).

A jerk-limited move is seven phases of one or two jerks per axis: +J, 0, −J, a cruise, −J′, 0, +J′.
A record says per axis, in two bits, whether its jerk is none, given (a varint), or its last jerk in
the frame again or negated; n and two flags share one varint; a state set carries its speed as the
change from the chain's (a corner's new speed, a landing's small correction). So a phase is 2 bytes
where it repeats a jerk and a three-axis jerk phase about 8, against 15 for a CUBIC_SEGMENT. A frame
is read in order once it is taken, against the chain its predecessors left, so a resent frame means
exactly what it meant the first time.

`SpeedChain` is what the host knows of the firmware's chain for this (each axis's I, d and
direction), `pack` the one canonical encoding and `expand` its meaning (the firmware's
`qs_cubic_records_next`, tests/firmware holds the two equal through protocol/vectors.json).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    model_serializer,
    model_validator,
)

from ..kernel.cubic_chain import CubicChain, CubicRefused, choose2
from ..kernel.fixed import CUBIC_N_MAX, JERK_LIMIT, MAX_AXES, SIGMA
from ..kernel.motion import CubicAxis
from .constants import MAX_FRAME, FieldId
from .cubic import CubicSegment
from .segment import Segment
from .varint import read_uvarint, svarint, unzigzag, uvarint
from .wire import FieldFault, RecordsField, Request, bits, four_axes, message

NONE, GIVEN, NEGATE, SAME = 0, 1, 2, 3  # an axis's jerk code
SETS = 0x01  # in n's varint: a sets byte follows (bits 0–3 axes set, 4–7 their directions)
ACCEL = 0x02  # in n's varint: each set axis has an acceleration after its speed
RECORDS_MAX = 16  # records in one frame
PAYLOAD_MAX = MAX_FRAME - 4  # type, seq and the CRC take the rest of a frame
MOST = {"head": 3, "speed": 5, "accel": 4, "jerk": 3}  # bytes a varint may take


class CubicRecord(BaseModel):
    """One record as on the wire: n, each axis's jerk code with the given jerks, and the sets."""

    model_config = ConfigDict(frozen=True)

    n: int = Field(ge=0, lt=1 << 19)
    codes: tuple[int, int, int, int] = Field(description="per axis: NONE, GIVEN, NEGATE or SAME")
    jerks: tuple[int, ...] = Field(default=(), description="per axis coded GIVEN, in axis order")
    sets: int | None = Field(
        default=None, ge=0, le=255, description="bits 0–3 axes set, 4–7 their directions"
    )
    speeds: tuple[int, ...] = Field(
        default=(), description="per set axis: the speed less the chain's"
    )
    accels: tuple[int, ...] | None = Field(
        default=None, description="per set axis: its acceleration"
    )

    @model_validator(mode="after")
    def _whole(self) -> CubicRecord:
        if any(not 0 <= c <= 3 for c in self.codes) or len(self.jerks) != self.codes.count(GIVEN):
            raise ValueError("a jerk code is 0..3, and each GIVEN has its jerk")
        if any(not -(1 << 20) <= j < 1 << 20 for j in self.jerks):
            raise ValueError("a jerk takes at most 3 bytes")
        count = len(bits((self.sets or 0) & 0x0F))
        if len(self.speeds) != count or (
            self.accels is not None and (not count or len(self.accels) != count)
        ):
            raise ValueError("a speed (and, with accels, an acceleration) for each set axis")
        if any(not -(1 << 31) <= s < 1 << 31 for s in self.speeds):
            raise ValueError("a speed change lies within ±2^31")
        if self.accels is not None and any(not -(1 << 27) <= a < 1 << 27 for a in self.accels):
            raise ValueError("an acceleration takes at most 4 bytes")
        return self

    @model_serializer(mode="wrap")
    def _only_what_is_there(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields the record carries, as protocol/vectors.json writes them."""
        return {k: v for k, v in handler(self).items() if v is not None and v != [] and v != ()}

    def pack(self) -> bytes:
        code_byte = sum(c << 2 * a for a, c in enumerate(self.codes))
        flags = (SETS if self.sets is not None else 0) | (ACCEL if self.accels is not None else 0)
        out = bytearray([code_byte]) + uvarint(self.n << 2 | flags)
        if self.sets is not None:
            out.append(self.sets)
            for k, speed in enumerate(self.speeds):
                out += svarint(speed)
                if self.accels is not None:
                    out += svarint(self.accels[k])
        for jerk in self.jerks:
            out += svarint(jerk)
        return bytes(out)


def _parse(payload: bytes, offset: int) -> tuple[list[CubicRecord], int] | None:
    """Every record from `offset` to the end, or None where one is not whole (BAD_LENGTH)."""
    records: list[CubicRecord] = []
    at = offset
    while at < len(payload):
        if len(records) == RECORDS_MAX:
            return None
        code_byte = payload[at]
        head = read_uvarint(payload, at + 1, MOST["head"])
        if head is None:
            return None
        value, at = head
        sets: int | None = None
        speeds: list[int] = []
        accels: list[int] | None = [] if value & ACCEL else None
        if value & SETS:
            if at >= len(payload):
                return None
            sets = payload[at]
            at += 1
            for _ in bits(sets & 0x0F):
                speed = read_uvarint(payload, at, MOST["speed"])
                if speed is None or speed[0] >> 32:
                    return None
                speeds.append(unzigzag(speed[0]))
                at = speed[1]
                if accels is not None:
                    accel = read_uvarint(payload, at, MOST["accel"])
                    if accel is None:
                        return None
                    accels.append(unzigzag(accel[0]))
                    at = accel[1]
        codes = four_axes([code_byte >> 2 * a & 3 for a in range(MAX_AXES)])
        jerks = []
        for _ in range(codes.count(GIVEN)):
            jerk = read_uvarint(payload, at, MOST["jerk"])
            if jerk is None:
                return None
            jerks.append(unzigzag(jerk[0]))
            at = jerk[1]
        records.append(
            CubicRecord(
                n=value >> 2,
                codes=codes,
                jerks=tuple(jerks),
                sets=sets,
                speeds=tuple(speeds),
                accels=None if sets is None or accels is None or not speeds else tuple(accels),
            )
        )
    return (records, at) if records else None


@dataclass(frozen=True)
class Records(RecordsField):
    """The records, to the end of the payload."""

    def parse(self, payload: bytes, offset: int) -> tuple[list[Any], int] | None:
        return _parse(payload, offset)

    def pack(self, value: tuple[CubicRecord, ...]) -> bytes:
        return b"".join(record.pack() for record in value)


@message(0x19, "CUBIC_SEGMENTS")
class CubicSegments(Request):
    """1 … 16 chained cubic segments (capability bit 12); each takes a queue slot, all or none."""

    model_config = ConfigDict(frozen=True, extra="ignore")

    records: Annotated[tuple[CubicRecord, ...], Records()]

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The firmware's checks, record by record, against the chain of a freshly started firmware
        (every axis at rest on the ideal); within a stream, against the chain reached."""
        expand(raw["records"], CubicChain(axis_count))

    def __len__(self) -> int:
        return len(self.records)


# --- the records' meaning -------------------------------------------------------------------------


def expand(records: Sequence[CubicRecord], chain: CubicChain) -> list[CubicSegment]:
    """The cubic segments the records mean, starting from `chain`, which they move on; raises
    FieldFault as the firmware refuses: N, AXES, DIRECTION, then SPEED per set axis and JERK per
    axis, then CUBIC_SEGMENT's own checks."""
    out: list[CubicSegment] = []
    last = [0] * MAX_AXES
    for record in records:
        if not 1 <= record.n <= CUBIC_N_MAX:
            raise FieldFault(FieldId.N, None, f"n = {record.n}, limit 1..{CUBIC_N_MAX}")
        sets = record.sets or 0
        named = bits(sets & 0x0F) + [a for a, c in enumerate(record.codes) if c]
        if any(a >= chain.axis_count for a in named):
            raise FieldFault(
                FieldId.AXES, None, f"axes {sorted(set(named))}, firmware has {chain.axis_count}"
            )
        if sets >> 4 & ~sets & 0x0F:
            raise FieldFault(
                FieldId.DIRECTION, None, f"direction bit of an axis not set (sets 0x{sets:02x})"
            )
        axes: dict[int, dict[str, Any]] = {}
        for k, axis in enumerate(bits(sets & 0x0F)):
            state = chain.axes[axis]
            direction = -1 if sets >> (4 + axis) & 1 else 1
            if not 0 <= state.i <= SIGMA:
                raise FieldFault(
                    FieldId.SPEED,
                    axis,
                    f"axis {axis}: the chain's speed {state.i} is outside 0 … 1 step",
                )
            speed = (state.i if direction == state.direction else -state.i) + record.speeds[k]
            if not 0 <= speed < SIGMA:
                raise FieldFault(
                    FieldId.SPEED, axis, f"axis {axis}: a set speed {speed} outside 0 … 1 step"
                )
            accel = record.accels[k] if record.accels is not None else 0
            axes[axis] = {"axis": axis, "speed": speed, "accel": accel, "direction": direction}
        given = iter(record.jerks)
        for axis, code in enumerate(record.codes):
            if code == NONE:
                continue
            jerk = next(given) if code == GIVEN else last[axis] if code == SAME else -last[axis]
            if not -JERK_LIMIT <= jerk < JERK_LIMIT:
                raise FieldFault(FieldId.JERK, axis, f"axis {axis}: jerk {jerk}, limit ±2^15")
            last[axis] = jerk
            axes.setdefault(axis, {"axis": axis})["jerk"] = jerk
        # built unvalidated: CubicChain.check names an acceleration outside 24 bits as the firmware
        # does
        segment = CubicSegment.model_construct(
            n=record.n,
            axes=tuple(
                CubicAxis.model_construct(
                    **{"accel": 0, "direction": 1, "speed": None, "jerk": None, **axes[a]}
                )
                for a in sorted(axes)
            ),
        )
        try:
            chain.advance(segment)
        except CubicRefused as refused:
            raise FieldFault(FieldId[refused.field], refused.axis, str(refused)) from None
        out.append(CubicSegment.model_validate(segment.model_dump()))
    return out


# --- what the host knows of the chain, and the one canonical packing ------------------------------


@dataclass
class SpeedChain:
    """Per axis what a record's set starts from: the firmware chain's I (the advance over the next
    tick, 2^-31 step), its change d and the direction; None where the host cannot know it (before
    the motion's first segment). A direction is needed only while I is not 0."""

    axis_count: int
    i: list[int | None] = field(default_factory=list)
    d: list[int | None] = field(default_factory=list)
    direction: list[int] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.i:
            self.forget()

    @classmethod
    def at_rest(cls, axis_count: int) -> SpeedChain:
        return cls(axis_count, [0] * axis_count, [0] * axis_count, [1] * axis_count)

    def forget(self) -> None:
        self.i = [None] * self.axis_count
        self.d = [None] * self.axis_count
        self.direction = [1] * self.axis_count

    def copy(self) -> SpeedChain:
        return SpeedChain(self.axis_count, list(self.i), list(self.d), list(self.direction))

    def follow(self, segment: Segment | CubicSegment) -> None:
        """After `segment`: a quadratic one leaves its axes at vn << 19 with no d and stops the
        others."""
        if isinstance(segment, Segment):
            moves = {a.axis: a for a in segment.axes}
            for axis in range(self.axis_count):
                move = moves.get(axis)
                self.i[axis], self.d[axis] = (move.vn << 19, 0) if move is not None else (0, 0)
                if move is not None:
                    self.direction[axis] = move.direction
            return
        named = {a.axis: a for a in segment.axes}
        for axis in range(self.axis_count):
            a = named.get(axis)
            r = 0
            if a is not None:
                if a.speed is not None:
                    self.i[axis], self.d[axis], self.direction[axis] = a.speed, a.accel, a.direction
                r = a.jerk or 0
            i, d = self.i[axis], self.d[axis]
            if i is not None and d is not None:
                self.i[axis] = i + segment.n * d + choose2(segment.n) * r
                self.d[axis] = d + segment.n * r

    def base(self, axis: int, direction: int) -> int | None:
        """The speed a set in `direction` starts from; None where unknown or outside 0 … 1 step."""
        i = self.i[axis]
        if i is None or not 0 <= i <= SIGMA:
            return None
        return 0 if i == 0 else i if direction == self.direction[axis] else -i


def _record(segment: CubicSegment, chain: SpeedChain, last: list[int]) -> CubicRecord | None:
    """The canonical record of `segment` from `chain`, `last` each axis's last jerk in the frame
    (moved on); None where a set cannot start from the chain (send the segment as a
    CUBIC_SEGMENT)."""
    sets, speeds, accels = 0, [], []
    for a in segment.axes:
        if a.speed is None:
            continue
        base = chain.base(a.axis, a.direction)
        if base is None or not -(1 << 31) <= a.speed - base < 1 << 31:
            return None
        sets |= 1 << a.axis | ((16 << a.axis) if a.direction < 0 else 0)
        speeds.append(a.speed - base)
        accels.append(a.accel)
    codes, jerks = [NONE] * MAX_AXES, []
    for a in segment.axes:
        jerk = a.jerk or 0
        if not jerk:
            continue
        if jerk == last[a.axis]:
            codes[a.axis] = SAME
        elif jerk == -last[a.axis]:
            codes[a.axis] = NEGATE
        else:
            codes[a.axis] = GIVEN
            jerks.append(jerk)
        last[a.axis] = jerk
    return CubicRecord(
        n=segment.n,
        codes=four_axes(codes),
        jerks=tuple(jerks),
        sets=sets if sets else None,
        speeds=tuple(speeds),
        accels=tuple(accels) if any(accels) else None,
    )


def pack(
    segments: Sequence[CubicSegment], chain: SpeedChain, limit: int = RECORDS_MAX
) -> CubicSegments | None:
    """As many of `segments` (from the first, at most `limit`) as one frame holds, moving `chain` on
    past them; None when the first cannot be a record (send it as a CUBIC_SEGMENT, then follow
    it)."""
    records: list[CubicRecord] = []
    size, last = 0, [0] * MAX_AXES
    for segment in segments[: min(limit, RECORDS_MAX)]:
        kept = list(last)
        record = _record(segment, chain, last)
        if record is None or size + len(record.pack()) > PAYLOAD_MAX:
            last[:] = kept
            break
        records.append(record)
        size += len(record.pack())
        chain.follow(segment)
    return CubicSegments(records=tuple(records)) if records else None
