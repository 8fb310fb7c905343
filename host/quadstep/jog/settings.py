"""Jog presets and the timeouts that turn terminal key repeats into a release."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator


class JogSettings(BaseModel):
    """What the jog keys do; every value is checked with a message naming it."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    # Distances of one incremental jog, mm (number keys 1, 2, ... select them).
    step_presets: tuple[float, ...] = Field(
        default=(0.01, 0.1, 1.0, 10.0), min_length=1, max_length=9
    )
    # Jog speeds as fractions of each axis's max_speed, slowest first.
    speed_presets: tuple[float, ...] = Field(
        default=(0.02, 0.1, 0.25, 0.5, 1.0), min_length=1, max_length=9
    )
    # A held key repeats only after the terminal's initial delay (typically 250–660 ms),
    # then every 30–50 ms: a continuous jog ends when no repeat came within these.
    first_repeat_timeout: float = Field(default=0.7, gt=0.0, le=5.0, description="s")
    repeat_timeout: float = Field(default=0.15, gt=0.0, le=5.0, description="s")
    # Motion queued on the board ahead of the machine during a continuous jog:
    # a host that vanishes leaves at most this much (then the board stops); a
    # busy host must get the next segment out within it, or the board underruns.
    lookahead: float = Field(default=0.25, ge=0.02, le=2.0, description="s")
    # Where the terminal reports no key release (Jogger.taps): a press moves only what the jog
    # speed covers in tap_time, at most tap_max; the jog goes on only when the key repeats.
    tap_time: float = Field(default=0.1, gt=0.0, le=1.0, description="s")
    tap_max: float = Field(default=1.0, gt=0.0, le=100.0, description="mm")

    @model_validator(mode="after")
    def _presets_in_range(self) -> JogSettings:
        for i, step in enumerate(self.step_presets):
            if not 0.0 < step <= 1000.0:
                raise ValueError(
                    f"step_presets[{i}] = {step}: must be greater than 0 and at most 1000 mm"
                )
        for i, speed in enumerate(self.speed_presets):
            if not 0.0 < speed <= 1.0:
                raise ValueError(
                    f"speed_presets[{i}] = {speed}: must be greater than 0 and at most 1 (the axis "
                    "max)"
                )
        if self.repeat_timeout > self.first_repeat_timeout:
            raise ValueError(
                f"repeat_timeout = {self.repeat_timeout}: must be at most first_repeat_timeout = "
                f"{self.first_repeat_timeout}"
            )
        return self
