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
from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import ConfigDict

from ..kernel.cubic_chain import CubicChain, CubicRefused
from ..kernel.fixed import CUBIC_N_MAX, MAX_AXES
from ..kernel.motion import Cubic, CubicAxis, CubicTicks
from .constants import FieldId
from .wire import FieldCodec, FieldFault, Int, Request, bits, message

SPEED_BIT = 1 << 31  # in a set's speed word: the axis moves in the negative direction
SET_BYTES = 7  # speed:u32, accel:i24
JERK_BYTES = 2  # jerk:i16


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
class CubicSegment(Cubic, Request):
    """A cubic segment (kernel/motion.py) on the wire: n:u16, then the named axes."""

    model_config = ConfigDict(frozen=True, extra="ignore")

    n: Annotated[CubicTicks, Int("H")]
    axes: Annotated[tuple[CubicAxis, ...], CubicFields()] = ()

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        """The firmware's checks in order: N and AXES, then ACCEL and SPEED against the state each
        axis carries, here that of a freshly started firmware (every axis at rest on the ideal);
        within a chain, kernel/cubic_chain.py's CubicChain checks against the state reached."""
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
            raise FieldFault(FieldId[refused.field], refused.axis, str(refused)) from None


__all__ = ["CubicFields", "CubicSegment"]
