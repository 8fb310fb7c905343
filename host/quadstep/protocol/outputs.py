"""The OUTPUTS message: the spindle (or laser) and coolant outputs, in stream order (PROTOCOL.md
§5.5)."""

from __future__ import annotations

from typing import Any

from ..kernel.fixed import D
from .constants import FieldId, Output
from .fields import U8, U16
from .wire import FieldFault, Request, message

VALID_BITS = int(Output.ON | Output.REVERSE | Output.DYNAMIC | Output.MIST | Output.FLOOD)


@message(0x17, "OUTPUTS")
class Outputs(Request):
    """The spindle (or laser) and coolant outputs for the segments sent after it, and at rest
    (PROTOCOL.md §5.5).

    `outputs` holds Output bits; `power` is the duty (0 … 65535). With Output.DYNAMIC the duty
    follows axis `axis`'s speed: `power` at `speed` (1/4096 step per tick, 1 … 4096) and in
    proportion below it; without it `axis` and `speed` are 0."""

    outputs: U8
    power: U16
    axis: U8 = 0
    speed: U16 = 0

    @classmethod
    def check_wire(cls, raw: dict[str, Any], axis_count: int) -> None:
        bits = raw["outputs"]
        unknown = bits & ~VALID_BITS
        if unknown:
            raise FieldFault(
                FieldId.OUTPUTS, None, f"outputs = 0x{bits:02x}: no output has bits 0x{unknown:02x}"
            )
        if bits & Output.DYNAMIC:
            if raw["axis"] >= axis_count:
                raise FieldFault(
                    FieldId.REFERENCE, raw["axis"], f"axis {raw['axis']}, firmware has {axis_count}"
                )
            if not 1 <= raw["speed"] <= D:
                raise FieldFault(
                    FieldId.REFERENCE, raw["axis"], f"speed = {raw['speed']}, limit 1..{D}"
                )
        elif raw["axis"] or raw["speed"]:
            raise FieldFault(
                FieldId.REFERENCE, None, "a power that follows no speed names no axis and no speed"
            )
