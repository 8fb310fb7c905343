"""The SEGMENT message: one quadratic per axis over n ticks (PROTOCOL.md §5.2)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

SPEED_SHIFT = 12
D = 1 << SPEED_SHIFT  # speed denominator: a speed v means v/D steps per tick
N_MAX = 1022  # longest segment in ticks; keeps every per-tick value inside 24 bits
R_MAX = D  # residual limit, in 1/(2D) step
MAX_AXES = 4


class AxisMove(BaseModel):
    """One axis of a segment: direction, start and end speed, starting residual."""

    model_config = ConfigDict(frozen=True)

    axis: int = Field(ge=0, lt=MAX_AXES)
    direction: Literal[1, -1]
    v0: int = Field(ge=0, le=D, description="start speed, v0/4096 steps per tick")
    vn: int = Field(ge=0, le=D, description="end speed, vn/4096 steps per tick")
    r: int = Field(ge=-R_MAX, le=R_MAX, description="starting residual, 1/8192 step, ahead is positive")

    @model_validator(mode="after")
    def _not_trailing_forever(self) -> AxisMove:
        if self.r == R_MAX and self.v0 == D and self.vn == D:
            raise ValueError("r = 4096 with v0 = vn = 4096 would trail the ideal by ½ step all segment")
        return self


class Segment(BaseModel):
    """n ticks of motion; axes not listed stay still."""

    model_config = ConfigDict(frozen=True)

    n: int = Field(ge=1, le=N_MAX)
    axes: tuple[AxisMove, ...] = ()

    @field_validator("axes")
    @classmethod
    def _ascending_unique(cls, axes: tuple[AxisMove, ...]) -> tuple[AxisMove, ...]:
        order = [a.axis for a in axes]
        if order != sorted(set(order)):
            raise ValueError(f"axes must be listed once each in ascending order, got {order}")
        return axes

    def moving_at_end(self) -> bool:
        """True when some axis still has speed at the end (an empty queue after it is an underrun)."""
        return any(a.vn > 0 for a in self.axes)
