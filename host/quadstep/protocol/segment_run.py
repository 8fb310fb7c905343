"""The SEGMENTS message: chained quadratic segments, several to a frame (PROTOCOL.md §5.2).

The segment before leaves every axis at a speed and a residual, which the firmware keeps exactly
(its chain); they are the next segment's v0 and r unless its record says otherwise. So a record
carries n and each axis's change of speed, in variable-length integers: a chained two-axis segment
is 4 bytes, a cruise 2, the same segment again 1; a change close to the negated last one in the
frame (a move's deceleration after its acceleration) is sent as the difference (MIRROR). A frame is
read in order once it is taken (never when parked), against the chain its predecessors left, so a
resent frame means exactly what it meant the first time.

`RunChain` is the host's model of that chain, `pack` the one canonical encoding and `expand` its
meaning (the firmware's `qs_segments_next`, tests/firmware holds the two equal through
protocol/vectors.json).
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

from ..kernel.fixed import V_MAX, D
from ..kernel.motion import AxisMove, Direction
from .constants import MAX_FRAME, FieldId
from .cubic import CubicSegment
from .cubic_run import SpeedChain
from .segment import Segment
from .varint import read_svarint, svarint
from .wire import FieldFault, RecordsField, Request, bits, message

N_HIGH = 0x03  # n's bits 8–9 in the head; its low byte follows
AXES = 0x04  # an axes byte follows (as SEGMENT's)
START = 0x08  # per axis: v0 less the chain's speed
RESIDUAL = 0x10  # per axis: r
CRUISE = 0x20  # vn = v0 on every axis: no vn field
REPEAT = 0x40  # the record before again (n, axes, v0, vn), its residuals from the chain
# per axis: vn − v0 plus the axis's last change in the frame (a deceleration undoing an
# acceleration)
MIRROR = 0x80
SEGMENTS_MAX = 16  # records in one frame
RUN_LIMIT = 8  # records a host puts in one frame, at most
PAYLOAD_MAX = MAX_FRAME - 4  # type, seq and the CRC take the rest of a frame
VARINT_LIMIT = 1 << 13  # |value| below this: a zigzag varint of at most two bytes
VARINT_MOST = 2  # bytes a varint of a record may take


Deltas = tuple[Annotated[int, Field(gt=-VARINT_LIMIT, lt=VARINT_LIMIT)], ...]


class SegmentRecord(BaseModel):
    """One record as on the wire: `repeat` alone, or n with what the chain does not say."""

    model_config = ConfigDict(frozen=True)

    repeat: bool = False
    n: int | None = Field(default=None, ge=0, le=1023)
    axes: int | None = Field(
        default=None, ge=0, le=255, description="the axes byte; None: the record before's"
    )
    start: Deltas | None = Field(
        default=None, description="per active axis: v0 less the chain's speed"
    )
    residual: Deltas | None = Field(default=None, description="per active axis: r")
    change: Deltas | None = Field(
        default=None, description="per active axis: vn − v0; None: a cruise"
    )
    mirror: bool = Field(
        default=False, description="change is vn − v0 plus the axis's last change in the frame"
    )

    @model_validator(mode="after")
    def _whole(self) -> SegmentRecord:
        if self.repeat != (self.n is None):
            raise ValueError("a record is a repeat (alone) or has an n")
        if self.repeat and (
            (self.axes, self.start, self.residual, self.change) != (None,) * 4 or self.mirror
        ):
            raise ValueError("a repeat carries nothing else")
        if self.mirror and self.change is None:
            raise ValueError("a mirrored change needs a change (not a cruise)")
        return self

    @model_serializer(mode="wrap")
    def _only_what_is_there(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """The fields the record carries, as protocol/vectors.json writes them."""
        return {k: v for k, v in handler(self).items() if v is not None and v is not False}

    def pack(self, active: int) -> bytes:
        """Its bytes, `active` axes having fields (the record's own axes byte, or the one
        before's)."""
        if self.repeat:
            return bytes([REPEAT])
        assert self.n is not None
        head = (
            self.n >> 8
            | (AXES if self.axes is not None else 0)
            | (START if self.start is not None else 0)
        )
        head |= (RESIDUAL if self.residual is not None else 0) | (
            CRUISE if self.change is None else 0
        )
        head |= MIRROR if self.mirror else 0
        out = bytearray([head, self.n & 0xFF])
        if self.axes is not None:
            out.append(self.axes)
        for j in range(active):
            for values in (self.start, self.residual, self.change):
                if values is not None:
                    out += svarint(values[j])
        return bytes(out)


def _active_count(axes: int) -> int:
    return len(bits(axes & 0x0F))


def _parse(payload: bytes, offset: int) -> tuple[list[SegmentRecord], int] | None:
    """Every record from `offset` to the end, or None where one is not whole (BAD_LENGTH)."""
    records: list[SegmentRecord] = []
    at, axes = offset, None
    while at < len(payload):
        head = payload[at]
        at += 1
        if len(records) == SEGMENTS_MAX or head & (MIRROR | CRUISE) == MIRROR | CRUISE:
            return None
        if head & REPEAT:
            if head != REPEAT or not records:
                return None
            records.append(SegmentRecord(repeat=True))
            continue
        if at >= len(payload):
            return None
        n = (head & N_HIGH) << 8 | payload[at]
        at += 1
        own_axes = None
        if head & AXES:
            if at >= len(payload):
                return None
            own_axes = axes = payload[at]
            at += 1
        elif axes is None:
            return None
        read = _read_fields(payload, at, head, _active_count(axes))
        if read is None:
            return None
        fields, at = read
        records.append(
            SegmentRecord(
                n=n,
                axes=own_axes,
                mirror=bool(head & MIRROR),
                start=fields["start"],
                residual=fields["residual"],
                change=fields["change"],
            )
        )
    return (records, at) if records else None


def _read_fields(
    payload: bytes, at: int, head: int, count: int
) -> tuple[dict[str, tuple[int, ...] | None], int] | None:
    """A record's start, residual and change fields (those its head names), one value per active
    axis each, interleaved by axis; None where one is not whole."""
    lists: dict[str, list[int] | None] = {
        name: [] if head & flag else None
        for name, flag in (("start", START), ("residual", RESIDUAL))
    }
    lists["change"] = None if head & CRUISE else []
    for _ in range(count):
        for name in ("start", "residual", "change"):
            values = lists[name]
            if values is not None:
                read = read_svarint(payload, at, VARINT_MOST)
                if read is None:
                    return None
                values.append(read[0])
                at = read[1]
    return {k: tuple(v) if v is not None else None for k, v in lists.items()}, at


@dataclass(frozen=True)
class Records(RecordsField):
    """The records, to the end of the payload."""

    def parse(self, payload: bytes, offset: int) -> tuple[list[Any], int] | None:
        return _parse(payload, offset)

    def pack(self, value: tuple[SegmentRecord, ...]) -> bytes:
        out, axes = bytearray(), 0
        for record in value:
            axes = record.axes if record.axes is not None else axes
            out += record.pack(_active_count(axes))
        return bytes(out)


@message(0x18, "SEGMENTS")
class Segments(Request):
    """1 … 16 chained quadratic segments (capability bit 11); each takes a queue slot, all or
    none."""

    model_config = ConfigDict(frozen=True, extra="ignore")

    records: Annotated[tuple[SegmentRecord, ...], Records()]

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The firmware's checks, record by record, against the chain of a freshly started firmware
        (every axis at rest on the ideal); within a stream, against the chain reached."""
        expand(raw["records"], RunChain.at_rest(axis_count))

    def __len__(self) -> int:
        return len(self.records)


# --- the chain, and the records' meaning ----------------------------------------------------------


@dataclass
class RunChain:
    """Per axis, what the firmware's chain gives a quadratic segment that starts from it: the speed
    (1/4096 step per tick) and the residual along the positive direction (1/8192 step); None where
    the host cannot know it (before the motion's first segment, after a cubic one). `speeds` is what
    it gives a cubic record's sets (CUBIC_SEGMENTS)."""

    axis_count: int
    speed: list[int | None] = field(default_factory=list)
    residual: list[int | None] = field(default_factory=list)
    speeds: SpeedChain | None = None

    def __post_init__(self) -> None:
        if not self.speed:
            self.forget()
        if self.speeds is None:
            self.speeds = SpeedChain(self.axis_count)

    @classmethod
    def at_rest(cls, axis_count: int) -> RunChain:
        chain = cls(axis_count, speeds=SpeedChain.at_rest(axis_count))
        chain.speed = [0] * axis_count
        chain.residual = [0] * axis_count
        return chain

    def forget(self) -> None:
        """The quadratic grid: after a cubic segment its end need not lie on it."""
        self.speed = [None] * self.axis_count
        self.residual = [None] * self.axis_count

    def copy(self) -> RunChain:
        assert self.speeds is not None
        return RunChain(self.axis_count, list(self.speed), list(self.residual), self.speeds.copy())

    def follow(self, segment: Segment) -> None:
        """After a quadratic segment: named axes end at vn and their exact residual, the others
        stop."""
        assert self.speeds is not None
        self.speeds.follow(segment)
        named = {a.axis: a for a in segment.axes}
        for axis in range(self.axis_count):
            move = named.get(axis)
            if move is None:
                self.speed[axis] = 0
                continue
            travel = move.r + segment.n * (move.v0 + move.vn)
            rest = travel - 2 * D * ((travel + D) // (2 * D))
            self.speed[axis] = move.vn
            self.residual[axis] = move.direction * rest

    def follow_cubic(self, segment: CubicSegment) -> None:
        assert self.speeds is not None
        self.speeds.follow(segment)
        self.forget()

    def known_speed(self, axis: int) -> int:
        """The speed on `axis`, where the chain is ready()."""
        speed = self.speed[axis]
        assert speed is not None, "a record starts only where every speed is known"
        return speed

    def ready(self) -> bool:
        """Whether a record can start from here (every speed known)."""
        return all(s is not None for s in self.speed)


def expand(records: Sequence[SegmentRecord], chain: RunChain) -> list[Segment]:
    """The segments the records mean, starting from `chain`, which they move on; raises FieldFault
    as the firmware refuses (AXES, DIRECTION, V0, VN, RESIDUAL per record, then SEGMENT's own
    checks)."""
    out: list[Segment] = []
    n, axes, v0, vn, last = 0, 0, [0] * 4, [0] * 4, [0] * 4
    for record in records:
        if not record.repeat:
            assert record.n is not None
            n = record.n
            axes = record.axes if record.axes is not None else axes
        active, negative = _check_axes(axes, chain.axis_count)
        moves: list[tuple[int, Direction, int, int, int]] = []
        for j, axis in enumerate(active):
            sign: Direction = -1 if negative >> axis & 1 else 1
            residual = chain.residual[axis]
            if not record.repeat:
                speed = chain.speed[axis]
                if speed is None:
                    raise FieldFault(
                        FieldId.V0, axis, "the chain's speed is not on the 1/4096 grid"
                    )
                v0[axis] = speed + (record.start[j] if record.start is not None else 0)
                if record.residual is not None:
                    residual = sign * record.residual[j]
                vn[axis] = v0[axis] + (record.change[j] if record.change is not None else 0)
                if record.mirror:
                    vn[axis] -= last[axis]
                if not 0 <= v0[axis] <= V_MAX:
                    raise FieldFault(FieldId.V0, axis, f"v0 = {v0[axis]}, limit 0..{V_MAX}")
                if not 0 <= vn[axis] <= V_MAX:
                    raise FieldFault(FieldId.VN, axis, f"vn = {vn[axis]}, limit 0..{V_MAX}")
            if residual is None:
                raise FieldFault(
                    FieldId.RESIDUAL, axis, "the chain's residual is not on the 1/8192 grid"
                )
            moves.append((axis, sign, v0[axis], vn[axis], sign * residual))
            if vn[axis] != v0[axis]:
                last[axis] = vn[axis] - v0[axis]
        raw = {"n": n, "axes": (axes, [(a, b, r) for _, _, a, b, r in moves])}
        Segment.check_wire(raw, chain.axis_count)
        segment = Segment(
            n=n,
            axes=tuple(AxisMove(axis=a, direction=s, v0=a0, vn=b, r=r) for a, s, a0, b, r in moves),
        )
        chain.follow(segment)
        out.append(segment)
    return out


def _check_axes(axes: int, axis_count: int) -> tuple[list[int], int]:
    """The active axes of an axes byte and its direction bits; raises FieldFault as the firmware
    refuses them (AXES, DIRECTION)."""
    active, negative = bits(axes & 0x0F), axes >> 4
    if any(a >= axis_count for a in active):
        raise FieldFault(FieldId.AXES, None, f"axes {active}, firmware has {axis_count}")
    if negative & ~axes & 0x0F:
        raise FieldFault(
            FieldId.DIRECTION, None, f"direction bit of an inactive axis (axes 0x{axes:02x})"
        )
    return active, negative


def _axes_byte(segment: Segment) -> int:
    return sum((1 << a.axis) | ((16 << a.axis) if a.direction < 0 else 0) for a in segment.axes)


def _shape(segment: Segment) -> tuple[int, int, tuple[tuple[int, int], ...]]:
    """What a REPEAT takes from the record before: n, the axes byte, and v0 and vn per axis."""
    return segment.n, _axes_byte(segment), tuple((a.v0, a.vn) for a in segment.axes)


def _record(
    segment: Segment, before: Segment | None, chain: RunChain, last: list[int]
) -> SegmentRecord:
    """The canonical record of `segment` after `before` (in the same frame) from `chain`."""
    residuals = [
        a.direction * residual if (residual := chain.residual[a.axis]) is not None else None
        for a in segment.axes
    ]
    chained = all(r == a.r for r, a in zip(residuals, segment.axes))
    if before is not None and chained and _shape(before) == _shape(segment):
        return SegmentRecord(repeat=True)
    axes = _axes_byte(segment)
    start = tuple(a.v0 - chain.known_speed(a.axis) for a in segment.axes)
    change, mirror = _change(segment, last)
    return SegmentRecord(
        n=segment.n,
        axes=axes if before is None or axes != _axes_byte(before) else None,
        start=start if any(start) else None,
        residual=None if chained else tuple(a.r for a in segment.axes),
        change=change,
        mirror=mirror,
    )


def _change(segment: Segment, last: list[int]) -> tuple[tuple[int, ...] | None, bool]:
    """The vn fields and whether they are mirrored (against each axis's last change in the frame):
    mirrored where that takes fewer bytes."""
    if all(a.vn == a.v0 for a in segment.axes):
        return None, False
    plain = tuple(a.vn - a.v0 for a in segment.axes)
    mirrored = tuple(c + last[a.axis] for c, a in zip(plain, segment.axes))
    if sum(map(len, map(svarint, mirrored))) < sum(map(len, map(svarint, plain))):
        return mirrored, True
    return plain, False


def pack(
    segments: Sequence[Segment], chain: RunChain, limit: int = SEGMENTS_MAX
) -> Segments | None:
    """As many of `segments` (from the first, at most `limit`) as one frame holds, moving `chain` on
    past them; None when the chain cannot start a record (send the first segment as a SEGMENT, then
    follow it)."""
    if not segments or not chain.ready():
        return None
    records: list[SegmentRecord] = []
    size, before, axes, last = 0, None, 0, [0] * 4
    for segment in segments[: min(limit, SEGMENTS_MAX)]:
        record = _record(segment, before, chain, last)
        axes = record.axes if record.axes is not None else axes
        length = len(record.pack(_active_count(axes)))
        if size + length > PAYLOAD_MAX:
            break
        records.append(record)
        size += length
        chain.follow(segment)
        for move in segment.axes:
            if move.vn != move.v0:
                last[move.axis] = move.vn - move.v0
        before = segment
    return Segments(records=tuple(records))
