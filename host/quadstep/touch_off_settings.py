"""The touch-off settings of a machine configuration (`[touch_off]`): the plate, the speeds and
distances of the touches (machine/touch_off.py runs them)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator


class TouchOffSettings(BaseModel):
    """Every distance in mm, every speed in mm/s."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    plate: float = Field(default=10.0, ge=0, le=100, description="mm, the touch plate's thickness")
    fast: float = Field(default=5.0, gt=0, le=100, description="mm/s, the first touch")
    slow: float = Field(default=0.5, gt=0, le=100, description="mm/s, the second touch")
    retract: float = Field(
        default=2.0, gt=0, le=50, description="mm backed off after the first touch"
    )
    distance: float = Field(
        default=40.0, gt=0, le=1000, description="mm, the farthest a first touch looks"
    )
    safe: float = Field(
        default=5.0, ge=0, le=200, description="mm above the surface a Z touch-off ends at"
    )
    depth: float = Field(
        default=5.0, gt=0, le=100, description="mm below the start an edge or a boss is probed at"
    )
    offset: float = Field(
        default=10.0,
        gt=0,
        le=500,
        description="mm along a face from the corner where a corner's faces are probed",
    )
    tool_diameter: float = Field(
        default=0.0, ge=0, le=100, description="mm, the tool or probe tip touching the edges"
    )

    @model_validator(mode="after")
    def _slow_below_fast(self) -> TouchOffSettings:
        if self.slow > self.fast:
            raise ValueError(f"slow = {self.slow:g}: must be at most fast = {self.fast:g} mm/s")
        return self
