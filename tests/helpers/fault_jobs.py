"""Jobs for the fault tests and the fault benchmark: many short moves, so that the link, not the motion, is what
a fault strains."""

from __future__ import annotations

import math


def engraving(moves: int, size: float = 100.0) -> str:
    """Short G1 moves (0.3–0.7 mm at size 100) along a Lissajous-like path around (size, size), and back."""
    out = ["G21 G90 F1500", f"G0 X{1.5 * size:.3f} Y{size:.3f}", "G1 Z-0.2 F300", "F1500"]
    for k in range(moves):
        a = k * 0.4 / size
        x = 1.5 * size + size * math.sin(a * 1.3) * math.cos(a * 0.021)
        out.append(f"G1 X{x:.3f} Y{size + 0.8 * size * math.sin(a * 0.9):.3f}")
    return "\n".join(out + ["G0 Z0", "G0 X0 Y0"]) + "\n"
