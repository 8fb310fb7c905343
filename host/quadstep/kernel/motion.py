"""Motion in the firmware's fixed-point form: a quadratic segment (constant acceleration, speeds in
1/D step per tick) and a cubic one (jerk-limited, advances in 2^-31 step), axis by axis. The wire
messages SEGMENT and CUBIC_SEGMENT (protocol/segment.py, protocol/cubic.py) are these models with
their bytes declared on them."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    field_validator,
    model_serializer,
    model_validator,
)

from .fixed import CUBIC_ACCEL_LIMIT, CUBIC_N_MAX, JERK_LIMIT, MAX_AXES, N_MAX, R_MAX, D

Direction = Literal[1, -1]  # an axis's sense of motion: +1 toward its positive steps

Ticks = Annotated[int, Field(ge=1, le=N_MAX)]  # a quadratic segment's length
CubicTicks = Annotated[int, Field(ge=1, le=CUBIC_N_MAX)]  # a cubic segment's length


class AxisMove(BaseModel):
    """One axis of a quadratic segment: direction, start and end speed, starting residual."""

    model_config = ConfigDict(frozen=True)

    axis: int = Field(ge=0, lt=MAX_AXES)
    direction: Direction
    v0: int = Field(ge=0, le=D, description="start speed, v0/4096 steps per tick")
    vn: int = Field(ge=0, le=D, description="end speed, vn/4096 steps per tick")
    r: int = Field(
        ge=-R_MAX, le=R_MAX, description="starting residual, 1/8192 step, ahead is positive"
    )

    @model_validator(mode="after")
    def _not_trailing_forever(self) -> AxisMove:
        if self.r == R_MAX and self.v0 == D and self.vn == D:
            raise ValueError(
                "r = 4096 with v0 = vn = 4096 would trail the ideal by ½ step all segment"
            )
        return self


def _ascending_unique(axes: tuple[Any, ...]) -> None:
    order = [a.axis for a in axes]
    if order != sorted(set(order)):
        raise ValueError(f"axes must be listed once each in ascending order, got {order}")


class Quadratic(BaseModel):
    """n ticks of constant acceleration; axes not listed stay still."""

    model_config = ConfigDict(frozen=True)

    n: Ticks
    axes: tuple[AxisMove, ...] = ()

    @field_validator("axes")
    @classmethod
    def _axes_in_order(cls, axes: tuple[AxisMove, ...]) -> tuple[AxisMove, ...]:
        _ascending_unique(axes)
        return axes

    def moving_at_end(self) -> bool:
        """True when some axis still has speed at the end (an empty queue after it is an
        underrun)."""
        return any(a.vn > 0 for a in self.axes)


class CubicAxis(BaseModel):
    """One named axis of a cubic segment: a state set (speed, accel, direction), a jerk, or both."""

    model_config = ConfigDict(frozen=True)

    axis: int = Field(ge=0, lt=MAX_AXES)
    speed: int | None = Field(
        default=None, ge=0, lt=1 << 31, description="set: advance over the first tick"
    )
    accel: int = Field(default=0, gt=-CUBIC_ACCEL_LIMIT, lt=CUBIC_ACCEL_LIMIT)
    direction: Direction = 1
    jerk: int | None = Field(default=None, ge=-JERK_LIMIT, lt=JERK_LIMIT)

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


class Cubic(BaseModel):
    """n ticks of jerk-limited motion; axes not listed keep their speed and acceleration, with no
    jerk."""

    model_config = ConfigDict(frozen=True)

    n: CubicTicks
    axes: tuple[CubicAxis, ...] = ()

    @field_validator("axes")
    @classmethod
    def _axes_in_order(cls, axes: tuple[CubicAxis, ...]) -> tuple[CubicAxis, ...]:
        _ascending_unique(axes)
        return axes


__all__ = ["AxisMove", "Cubic", "CubicAxis", "CubicTicks", "Direction", "Quadratic", "Ticks"]
