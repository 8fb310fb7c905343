"""Machine configuration: a TOML file validated by pydantic.

Every bad value is reported as one line naming the key, the value given and
the range allowed, e.g. `axes[0].max_speed = 900.0: must be at most 468.75
mm/s (3/4 step per tick at tick_hz 50000 with 80 steps/mm)`.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

if sys.version_info >= (3, 11):
    import tomllib
else:  # the same parser, as a package, before Python 3.11
    import tomli as tomllib

from .kernel.fixed import (
    CUBIC_ACCEL_LIMIT,
    CUBIC_SHIFT,
    DECEL_SHIFT,
    JERK_LIMIT,
    MAX_AXES,
    SPEED_SHIFT,
)
from .macro_settings import Macro
from .protocol.constants import AXIS_NAMES, POSITION_MAX
from .textfile import SETTINGS_MAX_BYTES, parse_nested, read_text
from .touch_off_settings import TouchOffSettings
from .validation import validate

AxisName = Literal["X", "Y", "Z", "A"]  # AXIS_NAMES, as pydantic needs them

# The planner lands every move exactly only while no axis moves more than
# 3/4 step per tick (docs/PLANNER.md, "Landing"); the firmware's own limit is 1.
MAX_STEPS_PER_TICK = 0.75
SIGMA = 1 << CUBIC_SHIFT  # one step in a cubic segment's units
CUBIC_JERK_LIMIT = JERK_LIMIT - 1  # a cubic segment's jerk field is an i16 (PROTOCOL.md §5.2)
# the smallest max_jerk, in units of the cubic segment's jerk (2^-31 step per tick³)
MIN_JERK_QUANTA = 64
MIN_STEPS_PER_MM = 1.0  # below it a 1 mm move may round to no step at all
SPEED_QUANTUM = 1 / (1 << SPEED_SHIFT)  # a segment's finest speed, step per tick
DECEL_QUANTUM = 1 / (1 << DECEL_SHIFT)  # a HOLD's gentlest deceleration, step per tick²


class ConfigError(ValueError):
    """A machine configuration that cannot be used; the message names every bad key."""


InputName = Literal[
    "limit_0",
    "limit_1",
    "limit_2",
    "limit_3",
    "limit_max_0",
    "limit_max_1",
    "limit_max_2",
    "limit_max_3",
    "probe",
    "abort",
    "feed_hold",
    "cycle_start",
]


class HomingConfig(BaseModel):
    """How an axis finds machine zero: the switch at one end of its travel (docs/INPUTS.md,
    Homing)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    end: Literal["min", "max"] = Field(
        default="min", description="which end of the travel the switch is at"
    )
    seek: float = Field(default=10.0, gt=0, description="mm/s, the fast approach")
    locate: float = Field(default=1.0, gt=0, description="mm/s, the slow approach that sets zero")
    pull_off: float = Field(
        default=1.0, gt=0, le=100, description="mm, backed off the switch after each approach"
    )
    switch_at: float | None = Field(
        default=None,
        description="mm, machine coordinate of the switch's point (default: pull_off beyond the "
        "travel's end)",
    )


class InputsConfig(BaseModel):
    """The board's inputs: polarity, debounce, which are used, hard limits (sent as CONFIG at
    connect)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    hard_limits: bool = True
    active_high: tuple[InputName, ...] = Field(
        default=(), description="inputs active when their pin is high (normally closed switches)"
    )
    disabled: tuple[InputName, ...] = Field(
        default=(), description="inputs ignored (nothing wired)"
    )
    debounce_ms: float = Field(default=0.0, ge=0, le=100, description="every input's debounce")


class BacklashConfig(BaseModel):
    """An axis's backlash and how it is taken up (docs/BACKLASH.md): at each reversal the motor
    makes the extra steps inside the motion, with an acceleration- and jerk-limited ramp; positions
    never include them."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    mm: float = Field(
        ge=0,
        le=10,
        description="the dead band: motor travel on a reversal before the carriage moves",
    )
    compensate: bool = Field(
        default=True, description="take it up at every reversal (false: measure only)"
    )
    accel: float | None = Field(
        default=None,
        gt=0,
        le=1_000_000,
        description="mm/s², the take-up's acceleration (default and most: the axis's max_accel)",
    )
    jerk: float | None = Field(
        default=None,
        gt=0,
        le=1e12,
        description="mm/s³, the take-up's jerk (default: its acceleration reached in 5 ms)",
    )
    place: Literal["around", "after"] = Field(
        default="around",
        description="around: centred on the reversal (smallest path error); "
        "after: begun where the axis reverses",
    )
    switch_hysteresis: float | None = Field(
        default=None,
        ge=0,
        le=10,
        description="mm, the limit switch's own hysteresis, calibrated once "
        "(quadstep backlash measure --method switch subtracts it)",
    )


class SendersConfig(BaseModel):
    """What `quadstep grbl` keeps for G-code senders between runs, as GRBL keeps it in EEPROM."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    status_mask: int = Field(
        default=1,
        ge=0,
        le=255,
        description="GRBL's $10: bit 0 set, status reports give MPos (clear: WPos); bit 1, Bf:",
    )


class SpindleConfig(BaseModel):
    """The spindle (or laser) output: what S means, and whether M4 is a laser's power that follows
    the speed."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    s_max: float = Field(
        default=1000.0, gt=0, le=1_000_000, description="S at full power (GRBL's $30)"
    )
    s_min: float = Field(
        default=0.0, ge=0, description="S below this runs at it (GRBL's $31); S0 is off"
    )
    laser: bool = Field(
        default=False,
        description="M3 constant power, M4 power following the speed, G0 off "
        "(GRBL's $32); false: M3 clockwise, M4 counter-clockwise",
    )
    spin_up_s: float = Field(
        default=0.0,
        ge=0,
        le=60,
        description="s to wait after the spindle is turned on before a job "
        "started at a line plunges (--from-line); 0: none",
    )
    overscan_mm: float = Field(
        default=0.0,
        ge=0,
        le=100,
        description="laser rasters: mm a row runs on at its speed, dark, before its first pixel "
        "and after its last, beyond what its ramps need",
    )

    @model_validator(mode="after")
    def _range_in_order(self) -> SpindleConfig:
        if self.s_min >= self.s_max:
            raise ValueError(f"s_min = {self.s_min:g}: must be less than s_max = {self.s_max:g}")
        return self

    def power(self, speed: float) -> int:
        """The duty (0 … 65535) for S = `speed`: 0 at S0, else in proportion to s_max, from s_min
        up."""
        if speed <= 0:
            return 0
        return round(65535 * min(1.0, max(speed, self.s_min) / self.s_max))


class AxisConfig(BaseModel):
    """One motor axis: its G-code letter, scale, limits and travel."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: AxisName
    steps_per_mm: float = Field(gt=0, le=100_000)
    max_speed: float = Field(gt=0, description="mm/s")
    max_accel: float = Field(gt=0, le=1_000_000, description="mm/s²")
    max_jerk: float | None = Field(
        default=None,
        gt=0,
        le=1e12,
        description="mm/s³: jerk-limited (S-curve) motion "
        "(docs/PLANNER.md); absent on every axis: constant acceleration",
    )
    travel_min: float = Field(ge=-100_000, le=100_000, description="mm")
    travel_max: float = Field(ge=-100_000, le=100_000, description="mm")
    invert: bool = False
    homing: HomingConfig | None = None  # None: the axis has no homing switch
    backlash: BacklashConfig | None = None  # None: no backlash known

    @property
    def backlash_steps(self) -> int:
        """The take-up in whole steps (0: none), rounded once."""
        if self.backlash is None or not self.backlash.compensate:
            return 0
        return math.floor(self.backlash.mm * self.steps_per_mm + 0.5)

    @property
    def switch_at(self) -> float | None:
        """The machine coordinate of the homing switch's point (None: no switch). By default the
        pull-off beyond the travel's end: homing leaves the axis at that end, and no move inside the
        travel (G53 Z0, G28, a park at the end) reaches the switch and stops on a hard limit."""
        if self.homing is None:
            return None
        if self.homing.switch_at is not None:
            return self.homing.switch_at
        if self.homing.end == "min":
            return self.travel_min - self.homing.pull_off
        return self.travel_max + self.homing.pull_off

    @model_validator(mode="after")
    def _consistent(self) -> AxisConfig:
        if self.steps_per_mm < MIN_STEPS_PER_MM:  # every other rule divides by it
            raise ValueError(
                f"steps_per_mm = {self.steps_per_mm:g}: must be at least "
                f"{MIN_STEPS_PER_MM:g} (a 1 mm move makes at least one step)"
            )
        problems = []
        if (
            self.backlash is not None
            and self.backlash.accel is not None
            and self.backlash.accel > self.max_accel
        ):
            problems.append(
                f"backlash.accel = {self.backlash.accel}: must be at most max_accel = "
                f"{self.max_accel}"
            )
        if self.travel_max <= self.travel_min:
            problems.append(
                f"travel_max = {self.travel_max}: must be greater than travel_min = "
                f"{self.travel_min}"
            )
        elif (self.travel_max - self.travel_min) * self.steps_per_mm < 1:
            step = 1 / self.steps_per_mm
            problems.append(
                f"travel_max = {self.travel_max:g}: must be at least one step "
                f"({step:g} mm) beyond travel_min = {self.travel_min:g}"
            )
        # the firmware keeps step positions within ±POSITION_MAX
        reach = POSITION_MAX / self.steps_per_mm
        for key, value in (("travel_min", self.travel_min), ("travel_max", self.travel_max)):
            if abs(value) > reach:
                problems.append(
                    f"{key} = {value:g}: must be within ±{reach:.0f} mm, the firmware's position "
                    f"range (±{POSITION_MAX} steps at {self.steps_per_mm:g} steps/mm)"
                )
        if problems:
            raise ValueError("\n".join(problems))  # every problem at once, a line each
        return self

    def to_steps(self, mm: float) -> int:
        """Step position of a machine coordinate, rounded once (half up), sign per `invert`."""
        steps = math.floor(mm * self.steps_per_mm + 0.5)
        return -steps if self.invert else steps

    def to_mm(self, steps: int) -> float:
        return (-steps if self.invert else steps) / self.steps_per_mm


class MachineConfig(BaseModel):
    """The whole machine: tick rate, axes in firmware order, cornering and arc rules."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    tick_hz: int = Field(ge=1000, le=1_000_000, description="must equal the firmware's tick rate")
    junction_deviation: float = Field(
        default=0.01, gt=0, le=10, description="mm, GRBL-style cornering"
    )
    arc_tolerance: float = Field(
        default=0.002, gt=0, le=10, description="mm, largest chord-to-arc distance"
    )
    axes: tuple[AxisConfig, ...] = Field(min_length=1, max_length=MAX_AXES)
    inputs: InputsConfig = InputsConfig()
    spindle: SpindleConfig = SpindleConfig()
    senders: SendersConfig = SendersConfig()  # quadstep grbl
    touch_off: TouchOffSettings = TouchOffSettings()  # machine/touch_off.py
    macros: tuple[Macro, ...] = Field(default=(), max_length=12)  # the TUI's user commands
    homing_order: tuple[AxisName, ...] | None = Field(
        default=None, description="default: Z first, then the others"
    )
    homing_required: bool = False  # refuse jobs and jogs until the machine is homed
    safe_z: float | None = Field(
        default=None,
        description="machine mm, the Z height a job started at a line "
        "travels at (--from-line); default: the top of Z's travel",
    )
    host_timeout: float = Field(
        default=1.0,
        ge=0,
        le=4,
        description="s: a host silent this long while the machine "
        "moves makes the firmware stop on its own (a hold, then ALARM HOST_LOST); 0: never "
        "(1 s: ten keep-alives missed, more than a busy host pauses)",
    )

    @model_validator(mode="after")
    def _axes_consistent(self) -> MachineConfig:
        problems = []
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            problems.append(f"axes: names must be unique, got {names}")
        for i, axis in enumerate(self.axes):
            limit = MAX_STEPS_PER_TICK * self.tick_hz / axis.steps_per_mm
            if axis.max_speed > limit:
                problems.append(
                    f"axes[{i}].max_speed = {axis.max_speed}: must be at most {limit:g} mm/s (3/4 "
                    f"step per tick at tick_hz {self.tick_hz} with {axis.steps_per_mm:g} steps/mm)"
                )
            problems += self._floors(i, axis)
            if axis.max_jerk is not None:
                self._check_cubic_range(i, axis)
        for name in self.homing_order or ():
            if name not in names:
                problems.append(f"homing_order: {name} is not an axis ({names})")
            elif self.axes[names.index(name)].homing is None:
                problems.append(f"homing_order: axis {name} has no [axes.homing]")
        if self.homing_required and not any(a.homing for a in self.axes):
            problems.append("homing_required = true: no axis has [axes.homing]")
        problems += self._safe_z_problems(names)
        problems += self._switch_problems()
        if problems:
            raise ValueError("\n".join(problems))  # every problem at once, a line each
        return self

    def _safe_z_problems(self, names: Sequence[str]) -> list[str]:
        if self.safe_z is None:
            return []
        if "Z" not in names:
            return [f"safe_z = {self.safe_z:g}: the machine has no Z axis ({names})"]
        z = self.axes[names.index("Z")]
        if not z.travel_min <= self.safe_z <= z.travel_max:
            return [
                f"safe_z = {self.safe_z:g}: must be within Z's travel "
                f"{z.travel_min:g} … {z.travel_max:g} mm"
            ]
        return []

    def _switch_problems(self) -> list[str]:
        """A homing switch placed inside its axis's travel: a move there (a park at the travel's
        end, the top of Z for --from-line and touch-off) would close it and, with hard limits,
        stop."""
        if not self.inputs.hard_limits:
            return []
        return [
            f"axes[{i}].homing.switch_at = {axis.homing.switch_at:g}: inside {axis.name}'s travel "
            f"{axis.travel_min:g} … {axis.travel_max:g} mm, where a move to it closes the switch "
            "and stops on ALARM HARD_LIMIT (hard_limits = true); leave switch_at out (it is then "
            "pull_off beyond the travel's end) or end the travel short of it"
            for i, axis in enumerate(self.axes)
            if axis.homing is not None
            and axis.homing.switch_at is not None
            and axis.travel_min <= axis.homing.switch_at <= axis.travel_max
        ]

    @property
    def clearance_z(self) -> float | None:
        """The machine Z a job started at a line travels at: safe_z, else the top of Z's travel
        (None: the machine has no Z)."""
        names = self.axis_names
        if "Z" not in names:
            return None
        return self.safe_z if self.safe_z is not None else self.axes[names.index("Z")].travel_max

    def _floors(self, i: int, axis: AxisConfig) -> list[str]:
        """Speeds of at least a segment's finest speed, accelerations at least a HOLD's gentlest
        deceleration (a hold could not brake more gently): a problem line for each below."""
        hz, spm = float(self.tick_hz), axis.steps_per_mm
        where = f"at tick_hz {self.tick_hz} with {spm:g} steps/mm"
        speed = (
            SPEED_QUANTUM * hz / spm,
            "mm/s",
            f"1/4096 step per tick, a segment's finest speed, {where}",
        )
        accel = (
            DECEL_QUANTUM * hz * hz / spm,
            "mm/s²",
            f"2^-24 step per tick², a hold's gentlest deceleration, {where}",
        )
        values = [("max_speed", axis.max_speed, speed), ("max_accel", axis.max_accel, accel)]
        if axis.homing is not None:
            values += [
                ("homing.seek", axis.homing.seek, speed),
                ("homing.locate", axis.homing.locate, speed),
            ]
        if axis.backlash is not None and axis.backlash.accel is not None:
            values.append(("backlash.accel", axis.backlash.accel, accel))
        return [
            f"axes[{i}].{key} = {value:g}: must be at least {least:.4g} {unit} ({why})"
            for key, value, (least, unit, why) in values
            if value < least
        ]

    def _check_cubic_range(self, i: int, axis: AxisConfig) -> None:
        """A jerk-limited plan runs as cubic segments: its jerk and acceleration must fit their
        fields."""
        hz = float(self.tick_hz)
        jerk_limit = CUBIC_JERK_LIMIT / SIGMA * hz**3 / axis.steps_per_mm
        if axis.max_jerk is not None and axis.max_jerk > jerk_limit:
            raise ValueError(
                f"axes[{i}].max_jerk = {axis.max_jerk:g}: must be at most {jerk_limit:g} mm/s³ "
                f"(a cubic segment's 16-bit jerk at tick_hz {self.tick_hz} with "
                f"{axis.steps_per_mm:g} steps/mm)"
            )
        jerk_floor = MIN_JERK_QUANTA / SIGMA * hz**3 / axis.steps_per_mm
        if axis.max_jerk is not None and axis.max_jerk < jerk_floor:
            raise ValueError(
                f"axes[{i}].max_jerk = {axis.max_jerk:g}: must be at least {jerk_floor:.4g} mm/s³ "
                f"({MIN_JERK_QUANTA} jerk quanta of a cubic segment at tick_hz {self.tick_hz} with "
                f"{axis.steps_per_mm:g} steps/mm, so that rounding it errs by under 1 %)"
            )
        accel_limit = CUBIC_ACCEL_LIMIT / SIGMA * hz * hz / axis.steps_per_mm / 2
        if axis.max_accel > accel_limit:
            raise ValueError(
                f"axes[{i}].max_accel = {axis.max_accel:g}: must be at most {accel_limit:g} mm/s² "
                "with max_jerk (half a cubic segment's 24-bit acceleration at tick_hz "
                f"{self.tick_hz})"
            )

    @property
    def jerk_limited(self) -> bool:
        """Plans are S-curves of cubic segments (some axis has max_jerk)."""
        return any(a.max_jerk is not None for a in self.axes)

    @property
    def homing_axes(self) -> tuple[int, ...]:
        """The axes to home, in order: homing_order, or Z first and then the others with
        [axes.homing]."""
        names = self.axis_names
        if self.homing_order is not None:
            return tuple(names.index(n) for n in self.homing_order)
        homed = [i for i, a in enumerate(self.axes) if a.homing is not None]
        return tuple(sorted(homed, key=lambda i: (names[i] != "Z", i)))

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def to_steps(self, position_mm: tuple[float, ...]) -> tuple[int, ...]:
        return tuple(a.to_steps(x) for a, x in zip(self.axes, position_mm))

    def to_mm(self, steps: tuple[int, ...] | list[int]) -> tuple[float, ...]:
        return tuple(a.to_mm(s) for a, s in zip(self.axes, steps))


def parse_config(data: dict[str, Any], source: str = "config") -> MachineConfig:
    return validate(MachineConfig, data, source, ConfigError)


def default_config(tick_hz: int, axis_count: int) -> MachineConfig:
    """A configuration for a board nothing is known about: 80 steps/mm, ±1000 mm, gentle limits."""
    speed = min(100.0, math.floor(MAX_STEPS_PER_TICK * tick_hz / 80))
    # fast ticks: a hold's least
    accel = max(500, math.ceil(DECEL_QUANTUM * tick_hz * tick_hz / 80))
    return parse_config(
        {
            "tick_hz": tick_hz,
            "axes": [
                {
                    "name": AXIS_NAMES[i],
                    "steps_per_mm": 80,
                    "max_speed": speed,
                    "max_accel": accel,
                    "travel_min": -1000,
                    "travel_max": 1000,
                }
                for i in range(axis_count)
            ],
        },
        DEFAULT_CONFIG_NAME,
    )


DEFAULT_CONFIG_NAME = "default configuration"


def load_config(path: Path) -> MachineConfig:
    """Read and validate a machine configuration file."""
    text = read_text(path, ConfigError, SETTINGS_MAX_BYTES)
    try:
        data = parse_nested(tomllib.loads, text, path, ConfigError)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    return parse_config(data, str(path))
