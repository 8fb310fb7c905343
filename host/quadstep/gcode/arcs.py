"""Arcs (G2/G3) as chords no farther than a tolerance from the true arc."""

from __future__ import annotations

import math

# A full circle of 100 m radius needs 15 708 chords at 0.002 mm; an arc needing more than this is
# refused (a radius of thousands of kilometres, which would be written out as millions of moves).
MAX_ARC_CHORDS = 100_000


def chord_count(radius: float, sweep: float, tolerance: float) -> int:
    """Chords needed so no chord strays more than `tolerance` from the arc (sagitta rule); more than
    MAX_ARC_CHORDS is counted as MAX_ARC_CHORDS + 1."""
    if radius <= tolerance:
        max_angle = math.pi / 2
    else:
        max_angle = 2.0 * math.acos(1.0 - tolerance / radius)  # 0 once tolerance / radius is tiny
    if max_angle <= 0.0 or abs(sweep) / max_angle > MAX_ARC_CHORDS:
        return MAX_ARC_CHORDS + 1
    return max(1, math.ceil(abs(sweep) / max_angle - 1e-9))


def sweep_angle(
    start: tuple[float, float],
    end: tuple[float, float],
    center: tuple[float, float],
    clockwise: bool,
) -> float:
    """Signed angle from start to end around center; a full turn when they coincide."""
    r0 = (start[0] - center[0], start[1] - center[1])
    r1 = (end[0] - center[0], end[1] - center[1])
    angle = math.atan2(r0[0] * r1[1] - r0[1] * r1[0], r0[0] * r1[0] + r0[1] * r1[1])
    if clockwise and angle >= -1e-9:
        angle -= 2.0 * math.pi
    elif not clockwise and angle <= 1e-9:
        angle += 2.0 * math.pi
    return angle


def radius_center(
    start: tuple[float, float], end: tuple[float, float], radius: float, clockwise: bool
) -> tuple[float, float] | None:
    """Center of the R-form arc (negative R: the longer way round); None if R cannot reach."""
    dx = end[0] - start[0]
    dy = end[1] - start[1]
    chord2 = dx * dx + dy * dy
    under = 4.0 * radius * radius - chord2
    if under < 0.0:
        if under > -1e-9 * max(1.0, chord2):
            under = 0.0
        else:
            return None
    h = -math.sqrt(under) / math.sqrt(chord2)
    if not clockwise:
        h = -h
    if radius < 0:
        h = -h
    # the center sits on the chord's perpendicular bisector, h·chord/2 from it
    return (start[0] + (dx - dy * h) / 2.0, start[1] + (dy + dx * h) / 2.0)
