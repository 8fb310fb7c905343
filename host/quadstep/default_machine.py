"""The machine quadstep assumes when no configuration is given: the router of
examples/router-uno.toml (a 3-axis CNC router on an Uno with a CNC shield, 400 steps/mm, at the Uno
firmware's 32 kHz). The emulator starts as this machine, so `quadstep run FILE --emulator` works
without a file; a real board needs one."""

from __future__ import annotations

from .config import MachineConfig, parse_config

DEFAULT_MACHINE_NAME = "the built-in default machine (the router of examples/router-uno.toml)"


def _axis(
    name: str, speed: float, accel: float, low: float, high: float, end: str, seek: float
) -> dict[str, object]:
    return {
        "name": name,
        "steps_per_mm": 400,
        "max_speed": speed,
        "max_accel": accel,
        "travel_min": low,
        "travel_max": high,
        "invert": False,
        "homing": {"end": end, "seek": seek, "locate": 1, "pull_off": 1},
    }


def default_machine() -> MachineConfig:
    return parse_config(
        {
            "tick_hz": 32000,
            "junction_deviation": 0.01,
            "arc_tolerance": 0.002,
            "inputs": {"hard_limits": True, "debounce_ms": 0.5},
            "axes": [
                _axis("X", 40, 500, 0, 300, "min", 20),
                _axis("Y", 40, 500, 0, 200, "min", 20),
                _axis("Z", 15, 200, -60, 0, "max", 10),
            ],
        },
        DEFAULT_MACHINE_NAME,
    )
