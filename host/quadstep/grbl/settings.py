"""`$$`: GRBL's settings as the machine's configuration says them (`$N=value` writes them into the
configuration file: settings_write.py)."""

from __future__ import annotations

from ..config import MachineConfig

NOT_KEPT = (
    "[MSG:quadstep: startup lines and settings resets are not kept; the file is the settings]"
)


def _mask(flags: list[bool]) -> int:
    return sum(1 << i for i, flag in enumerate(flags) if flag)


def _text(value: float) -> str:
    return str(int(value)) if float(value).is_integer() and abs(value) < 1e9 else f"{value:.3f}"


def settings(config: MachineConfig, status_mask: int = 1) -> list[tuple[int, float]]:
    """(number, value) of every setting, in GRBL's order; per-axis ones for every configured
    axis; $10 the session's."""
    axes = config.axes
    homing = [a.homing for a in axes if a.homing is not None]
    first = homing[0] if homing else None
    values: list[tuple[int, float]] = [
        (0, 10),
        (1, 25),
        (2, 0),
        (3, _mask([a.invert for a in axes])),
        (4, 0),
        (5, 0),
        (6, 0),
        (10, status_mask),
        (11, config.junction_deviation),
        (12, config.arc_tolerance),
        (13, 0),
        (20, 1),  # the travel is always checked, before anything moves
        (21, int(config.inputs.hard_limits)),
        (22, int(bool(homing))),
        # GRBL homes toward + unless the axis's bit is set (direction invert)
        (23, _mask([a.homing is not None and a.homing.end == "min" for a in axes])),
        (24, first.locate * 60 if first else 25),
        (25, first.seek * 60 if first else 500),
        (26, config.inputs.debounce_ms),
        (27, first.pull_off if first else 1),
        (30, config.spindle.s_max),
        (31, config.spindle.s_min),
        (32, int(config.spindle.laser)),
    ]
    for base, per_axis in (
        (100, [a.steps_per_mm for a in axes]),
        (110, [a.max_speed * 60 for a in axes]),
        (120, [a.max_accel for a in axes]),
        (130, [a.travel_max - a.travel_min for a in axes]),
    ):
        values += [(base + i, v) for i, v in enumerate(per_axis)]
    return values


def settings_lines(config: MachineConfig, status_mask: int = 1) -> list[str]:
    return [f"${number}={_text(value)}" for number, value in settings(config, status_mask)]
