"""The SEGMENT message: one quadratic per axis over n ticks (PROTOCOL.md §5.2)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import ConfigDict

from ..kernel.fixed import N_MAX, R_MAX, V_MAX
from ..kernel.motion import AxisMove, Quadratic, Ticks
from .constants import FieldId
from .wire import FieldFault, Int, Masked, Request, bits, message

__all__ = ["Segment", "SegmentAxes"]


@dataclass(frozen=True)
class SegmentAxes(Masked):
    """The `axes` byte (bits 0–3 active axes, bits 4–7 their directions, 1 = negative), then
    v0:u16, vn:u16, r:i16 for each active axis in axis order."""

    unit_code: str = "HHh"
    mask_bits: int = 0x0F

    def pack(self, value: tuple[AxisMove, ...]) -> bytes:
        mask = 0
        flat: list[int] = []
        for a in value:
            mask |= 1 << a.axis
            if a.direction < 0:
                mask |= 1 << (4 + a.axis)
            flat += (a.v0, a.vn, a.r)
        return self.pack_raw(mask, flat)

    def value(self, raw: Any) -> tuple[AxisMove, ...]:
        mask, items = raw
        return tuple(
            AxisMove(axis=axis, direction=-1 if mask >> (4 + axis) & 1 else 1, v0=v0, vn=vn, r=r)
            for axis, (v0, vn, r) in zip(bits(mask & 0x0F), items)
        )


@message(0x10, "SEGMENT")
class Segment(Quadratic, Request):
    """A quadratic segment (kernel/motion.py) on the wire: n:u16, then the axes."""

    model_config = ConfigDict(frozen=True, extra="ignore")

    n: Annotated[Ticks, Int("H")]
    axes: Annotated[tuple[AxisMove, ...], SegmentAxes()] = ()

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The firmware's checks, in the order of PROTOCOL.md §5.2: N, AXES, DIRECTION, then field
        by field (every V0, then every VN, then every RESIDUAL), each in axis order."""
        n = raw["n"]
        mask, items = raw["axes"]
        if not 1 <= n <= N_MAX:
            raise FieldFault(FieldId.N, None, f"n = {n}, limit 1..{N_MAX}")
        active = bits(mask & 0x0F)
        if any(a >= axis_count for a in active):
            raise FieldFault(FieldId.AXES, None, f"axes {active}, firmware has {axis_count}")
        if mask >> 4 & ~mask & 0x0F:
            raise FieldFault(
                FieldId.DIRECTION, None, f"direction bit of an inactive axis (mask 0x{mask:02x})"
            )
        fields = [(axis, *item) for axis, item in zip(active, items)]
        for axis, v0, _, _ in fields:
            if v0 > V_MAX:
                raise FieldFault(FieldId.V0, axis, f"v0 = {v0}, limit {V_MAX}")
        for axis, _, vn, _ in fields:
            if vn > V_MAX:
                raise FieldFault(FieldId.VN, axis, f"vn = {vn}, limit {V_MAX}")
        for axis, v0, vn, r in fields:
            if not -R_MAX <= r <= R_MAX or (r == R_MAX and v0 == V_MAX and vn == V_MAX):
                raise FieldFault(FieldId.RESIDUAL, axis, f"r = {r} with v0 = {v0}, vn = {vn}")
