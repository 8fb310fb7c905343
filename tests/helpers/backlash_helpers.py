"""Shared by the backlash tests and benchmark: a machine with backlash, the jobs that show it (a circle, a
pocket), a simulated machine whose carriages sit on the + side of their bands, and the carriage's path error
from the emulator's trace."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from quadstep.backlash.band import Band
from quadstep.config import AxisConfig, BacklashConfig, MachineConfig

TICK_HZ = 32_000
STEPS_PER_MM = 400


def backlash_config(mm: tuple[float, ...], accel: float = 500.0, compensate: bool = True) -> MachineConfig:
    """A router like examples/router-uno.toml (400 steps/mm), with `mm` of backlash on each axis."""
    return MachineConfig(
        tick_hz=TICK_HZ,
        axes=tuple(
            AxisConfig(name="XYZA"[i], steps_per_mm=STEPS_PER_MM, max_speed=40, max_accel=accel,
                       travel_min=-1000, travel_max=1000,
                       backlash=BacklashConfig(mm=b, compensate=compensate) if b else None)
            for i, b in enumerate(mm)
        ),
    )


def pushed_plus(config: MachineConfig) -> Band:
    """Every carriage pushed in + (the simulated machine of `sim_text` starts so)."""
    band = Band.of(config)
    return Band(tuple(replace(a, w=a.size, base=-a.size) for a in band.axes))


def sim_text(backlash_steps: tuple[float, ...], extra: str = "") -> str:
    """A simulated machine: each axis at 0 with its carriage on the + side of a band of that many steps."""
    return "".join(f"[[axis]]\nstart = 0\ncarriage = {-b / 2}\nbacklash = {b}\n" for b in backlash_steps) + extra


def write_sim(path: Path, backlash_steps: tuple[float, ...], extra: str = "") -> Path:
    path.write_text(sim_text(backlash_steps, extra))
    return path


def circle_gcode(radius: float, feed: float, turns: int = 1) -> str:
    """From the origin to (−radius, 0), full circles about the origin (G2), and back."""
    return "G21 G90\nG0 X%.3f Y0\n" % -radius + f"G2 X{-radius:.3f} Y0 I{radius:.3f} J0 F{feed * 60:g}\n" * turns \
        + "G0 X0 Y0\n"


def pocket_gcode(width: float, height: float, stepover: float, feed: float) -> str:
    """A rectangular pocket cleared in passes along X with stepovers along Y (a zigzag), from the origin."""
    lines = ["G21 G90", "G1 X0 Y0 F%g" % (feed * 60)]
    y, forward = 0.0, True
    while y <= height + 1e-9:
        lines.append(f"G1 X{width if forward else 0:.3f} Y{y:.3f}")
        y += stepover
        if y <= height + 1e-9:
            lines.append(f"G1 X{width if forward else 0:.3f} Y{y:.3f}")
        forward = not forward
    lines.append("G0 X0 Y0")
    return "\n".join(lines) + "\n"


def zigzag_gcode(passes: int, length: float, step: float, feed: float) -> str:
    """Passes back and forth along X, each `step` further along Y (a raster's zigzag: X reverses sharply at every
    tip, with no stepover between), from the origin and back."""
    lines = ["G21 G90", "G1 X0 Y0 F%g" % (feed * 60)]
    lines += [f"G1 X{length if k % 2 == 0 else 0:.3f} Y{(k + 1) * step:.3f}" for k in range(passes)]
    lines.append("G0 X0 Y0")
    return "\n".join(lines) + "\n"


def zigzag_path(passes: int, length: float, step: float) -> np.ndarray:
    """The zigzag's corners in order (mm), for its path error."""
    return np.array([(0.0, 0.0)] + [(length if k % 2 == 0 else 0.0, (k + 1) * step) for k in range(passes)])


def pocket_path(width: float, height: float, stepover: float) -> np.ndarray:
    """The pocket's corners in order (mm), for its path error."""
    points, y, forward = [(0.0, 0.0)], 0.0, True
    while y <= height + 1e-9:
        points.append((width if forward else 0.0, y))
        y += stepover
        if y <= height + 1e-9:
            points.append((width if forward else 0.0, y))
        forward = not forward
    return np.array(points)


def carriage_xy(rows: np.ndarray, start: tuple[float, float] = (0.0, 0.0)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(tick, x, y) of the carriage after every tick with a step, from a trace with a machine (steps); `start`
    is where each carriage was before its first step."""
    ticks, axes, carriage = rows[:, 0], rows[:, 1].astype(int), rows[:, 4]
    x = np.where(axes == 0, carriage, np.nan)
    y = np.where(axes == 1, carriage, np.nan)
    x = _fill(x, start[0])
    y = _fill(y, start[1])
    last = np.flatnonzero(np.diff(ticks, append=ticks[-1] + 1))  # after every step of a tick
    return ticks[last], x[last], y[last]


def _fill(values: np.ndarray, start: float) -> np.ndarray:
    index = np.where(np.isnan(values), 0, np.arange(values.size))
    np.maximum.accumulate(index, out=index)
    out = values[index]
    return np.where(np.isnan(out), start, out)


def radial_error(x: np.ndarray, y: np.ndarray, radius_steps: float) -> np.ndarray:
    return np.hypot(x, y) - radius_steps


def polyline_error(x: np.ndarray, y: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Distance of each point from the polyline through `corners` (same units)."""
    best = np.full(x.shape, np.inf)
    for (ax, ay), (bx, by) in zip(corners[:-1], corners[1:]):
        dx, dy = bx - ax, by - ay
        length = dx * dx + dy * dy
        t = np.clip(((x - ax) * dx + (y - ay) * dy) / length, 0, 1) if length else np.zeros(x.shape)
        best = np.minimum(best, np.hypot(x - (ax + t * dx), y - (ay + t * dy)))
    return best
