"""`$N=value`: a GRBL setting written into the machine's configuration file (config_file.set_values,
comments kept, the old file as FILE.bak), checked whole first, then used for the lines that follow.

Each writable setting is a key of the file: `$100`… steps/mm, `$110`… max rate (mm/min → max_speed
mm/s), `$120`… acceleration, `$130`… travel (the end of the travel nearer machine zero kept), `$11`
junction deviation, `$12` arc tolerance, `$21` hard limits, `$23` homing direction invert mask (bit
set: toward min), `$24`/`$25` homing speeds (mm/min), `$26` debounce, `$27` pull-off, `$30`/`$31`
spindle S range, `$32` laser mode, `$10` the status reports' fields ([senders] status_mask). The
others are fixed: writing the value they show is accepted (a
sender restoring settings), any other is refused with a message saying so."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..config import AxisConfig, ConfigError, MachineConfig
from ..config_file import Key, set_values
from ..machine import Machine, MachineError
from ..machine.reconfigure import adopt_config, check_config
from .errors import GrblError
from .settings import settings

SETTING_WRITE = re.compile(r"^\$(\d+)=(.*)$")
STATUS_MASK = 10  # $10, the status reports' fields
NUMBER = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)\s*$")
Values = dict[Key, float | bool | str]


class SettingError(ValueError):
    """A write refused: `error` is GRBL's number, the message names the setting and why."""

    def __init__(self, message: str, error: GrblError) -> None:
        super().__init__(message)
        self.error = error


@dataclass(frozen=True)
class SettingWrite:
    number: int
    value: float


def parse_write(text: str) -> SettingWrite | None:
    """`$N=value` → its number and value (SettingError for a value that is not a number); None for
    any other line."""
    match = SETTING_WRITE.match(text.strip())
    if match is None:
        return None
    number, value = int(match.group(1)), match.group(2)
    if not NUMBER.match(value):
        raise SettingError(f"${number}={value}: the value is not a number", GrblError.BAD_NUMBER)
    return SettingWrite(number, float(value))


def _flag(write: SettingWrite) -> bool:
    if write.value not in (0.0, 1.0):
        raise SettingError(
            f"${write.number}={write.value:g}: 0 (off) or 1 (on) only", GrblError.INVALID_STATEMENT
        )
    return write.value == 1.0


def _travel(axis: AxisConfig, length: float) -> Values:
    """$13x: the travel's length; its end nearer machine zero stays."""
    name = axis.name
    if abs(axis.travel_max) < abs(axis.travel_min):
        return {("axes", name, "travel_min"): axis.travel_max - length}
    return {("axes", name, "travel_max"): axis.travel_min + length}


def _per_axis(config: MachineConfig, write: SettingWrite) -> Values | None:
    group, index = divmod(write.number, 10)
    if group not in (10, 11, 12, 13) or index >= len(config.axes):
        return None
    axis = config.axes[index]
    if group == 13:
        return _travel(axis, write.value)
    key, scale = {10: ("steps_per_mm", 1.0), 11: ("max_speed", 1 / 60), 12: ("max_accel", 1.0)}[
        group
    ]
    return {("axes", axis.name, key): write.value * scale}


def _homing(config: MachineConfig, write: SettingWrite) -> Values | None:
    homed = [a for a in config.axes if a.homing is not None]
    if write.number == 23:
        mask = int(write.value)
        return {
            ("axes", a.name, "homing", "end"): "min" if mask >> i & 1 else "max"
            for i, a in enumerate(config.axes)
            if a.homing is not None
        }
    key, scale = {24: ("locate", 1 / 60), 25: ("seek", 1 / 60), 27: ("pull_off", 1.0)}[write.number]
    return {("axes", a.name, "homing", key): write.value * scale for a in homed}


def changes(config: MachineConfig, write: SettingWrite) -> Values | None:
    """The keys of the file that `write` sets; {} when it sets a fixed setting to the value it
    has; None when it is not a setting."""
    number, value = write.number, write.value
    if value < 0:
        raise SettingError(
            f"${number}={value:g}: a setting is never negative", GrblError.NEGATIVE_VALUE
        )
    simple: dict[int, Key] = {
        11: ("junction_deviation",),
        12: ("arc_tolerance",),
        26: ("inputs", "debounce_ms"),
        30: ("spindle", "s_max"),
        31: ("spindle", "s_min"),
    }
    flags: dict[int, Key] = {21: ("inputs", "hard_limits"), 32: ("spindle", "laser")}
    if number in simple:
        return {simple[number]: value}
    if number == STATUS_MASK:
        if not value.is_integer() or value > 255:
            raise SettingError(
                f"$10={value:g}: the status report mask is a whole number 0 … 255",
                GrblError.INVALID_STATEMENT,
            )
        return {} if value == config.senders.status_mask else {("senders", "status_mask"): value}
    if number in flags:
        return {flags[number]: _flag(write)}
    if number in (23, 24, 25, 27):
        if not any(a.homing is not None for a in config.axes):
            raise SettingError(
                f"${number}: no axis homes; homing is set per axis in [axes.homing]",
                GrblError.HOMING_DISABLED,
            )
        return _homing(config, write)
    per_axis = _per_axis(config, write)
    if per_axis is not None:
        return per_axis
    shown = dict(settings(config))
    if number not in shown:
        return None
    if shown[number] == value:
        return {}
    raise SettingError(
        f"${number} is fixed at {shown[number]:g} in quadstep", GrblError.INVALID_STATEMENT
    )


NO_FILE = (
    "quadstep: settings are written to the configuration file; start quadstep grbl with "
    "--config FILE to write them"
)


def write_setting(machine: Machine, path: Path | None, write: SettingWrite) -> bool:
    """Write `write` into the file at `path` and use it on `machine` (at rest); False when nothing
    changed (a fixed setting written with its value). SettingError when refused: nothing written."""
    values = changes(machine.config, write)
    if values is None:
        raise SettingError(f"${write.number}: no such setting", GrblError.INVALID_STATEMENT)
    if not values:
        return False
    if path is None:
        raise SettingError(NO_FILE, GrblError.INVALID_STATEMENT)
    source = str(path)
    try:
        config = set_values(path, values, lambda new: check_config(machine, new, source))
        adopt_config(machine, config, source)
    except (ConfigError, MachineError) as exc:
        reason = " ".join(str(exc).split())
        raise SettingError(
            f"${write.number}={write.value:g}: {reason}", GrblError.INVALID_STATEMENT
        ) from None
    return True
