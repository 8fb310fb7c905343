"""The RASTER message: a laser line at the chain's speed with a power per pixel (PROTOCOL.md §5.2,
capability bit 14).

The motion is the chain's cruise for `n` ticks on the axes `axes` names (a SEGMENTS record with
CRUISE and nothing else); the pixels are counted on the axis `pixel` names, the one with most
steps: pixel 0 from the line's start, pixel k (k ≥ 1) from the step that brings that axis
⌊(phase + (k − 1)·pitch) / 256⌋ steps from where the line began, the last one to the line's end.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Protocol

from pydantic import ConfigDict, Field

from ..kernel.fixed import N_MAX, D
from .constants import FieldId
from .fields import U8, U16
from .segment import Segment
from .wire import FieldCodec, FieldFault, Request, bits, message

HEAD = 8  # n:u16, axes, pixel, phase:u16, pitch:u16
PIXELS_MAX = 64 - 4 - HEAD  # a frame's 64 bytes less type, seq and CRC
STEP = 256  # phase and pitch are in 1/256 step


@dataclass(frozen=True)
class Powers(FieldCodec):
    """One power byte per pixel, to the end of the payload (at least one)."""

    def length(self, payload: bytes, offset: int) -> int | None:
        return len(payload) - offset if len(payload) > offset else None

    def pack(self, value: Sequence[int]) -> bytes:
        return bytes(value)

    def unpack(self, payload: bytes, offset: int, size: int) -> Any:
        return tuple(payload[offset : offset + size])


@message(0x1A, "RASTER")
class Raster(Request):
    """A line at the speed the chain leaves, `n` ticks, with `power[k]` (0 … 255, the duty's high
    byte) over pixel k; one queue slot."""

    model_config = ConfigDict(frozen=True)

    n: U16
    axes: U8
    pixel: U8
    phase: U16
    pitch: U16
    power: Annotated[tuple[int, ...], Field(min_length=1, max_length=PIXELS_MAX), Powers()]

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """What the line says by itself; its speeds are the chain's (`line_fault`)."""
        if not 1 <= raw["n"] <= N_MAX:
            raise FieldFault(FieldId.N, None, f"n = {raw['n']}, limit 1..{N_MAX}")
        active, negative = raw["axes"] & 0x0F, raw["axes"] >> 4
        if active >> axis_count:
            raise FieldFault(FieldId.AXES, None, f"axes 0x{active:x}, firmware has {axis_count}")
        if negative & ~active:
            raise FieldFault(FieldId.DIRECTION, None, "a direction for an axis that does not move")


def boundaries(phase: int, pitch: int, count: int) -> list[int]:
    """The steps from the line's start at which pixels 1 … count − 1 begin."""
    return [(phase + (k - 1) * pitch) // STEP for k in range(1, count)]


def cruise_steps(speed: int, residual: int, n: int) -> int:
    """Steps of an axis cruising at `speed` (1/4096 step a tick) from `residual` (1/8192 step)
    over n ticks (PROTOCOL.md §8)."""
    return (residual + 2 * speed * n + D) // (2 * D)


def line_fault(line: Raster, speeds: Sequence[int], residuals: Sequence[int]) -> FieldId | None:
    """The firmware's checks of the line against the chain's speed and residual per axis
    (RASTER_AXIS, then PIXELS), or None."""
    axis = line.pixel & 3
    active = bits(line.axes & 0x0F)
    if line.pixel > 3 or axis not in active or speeds[axis] == 0:
        return FieldId.RASTER_AXIS
    if any(speeds[a] > speeds[axis] for a in active):
        return FieldId.RASTER_AXIS
    if line.pitch < STEP or not STEP <= line.phase <= line.pitch:
        return FieldId.PIXELS
    last = boundaries(line.phase, line.pitch, len(line.power))
    if last and last[-1] > cruise_steps(speeds[axis], residuals[axis], line.n):
        return FieldId.PIXELS
    return None


class RasterLine(Segment):
    """A cruise the plan runs as a RASTER: the segment it is (for predictions and the chain) and
    the message that sends it."""

    raster: Raster


def raster_pixels(segment: object) -> int:
    """The powers `segment` carries to the board's ring: a RASTER line's, else none."""
    return len(segment.raster.power) if isinstance(segment, RasterLine) else 0


class _Source(Protocol):
    def pixels(self, i: int) -> int: ...


def ring_fits(source: _Source, start: int, last: int, ring: int) -> bool:
    """Whether the powers of the RASTER lines among segments `start` … `last` fit together in the
    board's ring of `ring` powers (IDENTIFY_REPLY's raster_ring; a line waits for room, else
    QUEUE_FULL). Asked at every report while a motion waits for room: `pixels` builds no
    segment."""
    return sum(source.pixels(i) for i in range(max(0, start), last + 1)) <= ring
