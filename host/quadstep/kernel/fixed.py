"""The fixed-point form of motion: denominators, shifts and the limits that keep every per-tick
value of the firmware inside its integer widths (docs/FIXED_POINT.md, docs/CUBIC.md). The wire
carries these numbers as they are, so protocol/constants.py names them too."""

from __future__ import annotations

MAX_AXES = 4  # axes a segment can name
SPEED_SHIFT = 12
D = 1 << SPEED_SHIFT  # speed denominator: a speed v means v/D steps per tick
V_MAX = D  # one step per tick
N_MAX = 1022  # longest segment in ticks; keeps every per-tick value inside 24 bits
R_MAX = D  # residual limit, in 1/(2D) step
DECEL_SHIFT = 24  # a HOLD deceleration d means d / 2^24 step per tick²
DECEL_MAX = 8191  # largest HOLD deceleration (keeps the hold's per-tick values inside 24 bits)
CUBIC_SHIFT = 31  # a cubic segment's advances are in 2^-31 step
SIGMA = 1 << CUBIC_SHIFT  # one step, in a cubic segment's units
HALF = SIGMA // 2
CUBIC_ACCEL_LIMIT = 1 << 23  # |change of the advance per tick| stays below this (24 bits)
CUBIC_N_MAX = 65535  # longest cubic segment in ticks (a 16-bit count)
JERK_LIMIT = 1 << 15  # |jerk| of a cubic segment stays below this (16 bits)

__all__ = [
    "CUBIC_ACCEL_LIMIT",
    "CUBIC_N_MAX",
    "CUBIC_SHIFT",
    "D",
    "DECEL_MAX",
    "DECEL_SHIFT",
    "HALF",
    "JERK_LIMIT",
    "MAX_AXES",
    "N_MAX",
    "R_MAX",
    "SIGMA",
    "SPEED_SHIFT",
    "V_MAX",
]
