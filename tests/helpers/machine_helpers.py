"""Helpers for the tests with a simulated machine: a machine file, moves planned by the host's planner, and the
exit summary's machine section."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from quadstep.config import AxisConfig, MachineConfig
from quadstep.planner.plan import plan_program
from quadstep.planner.program import LinearMove, Program
from quadstep.protocol import Segment

TICK_HZ = 32_000
STEPS_PER_MM = 400


def machine_config(axes: int = 3) -> MachineConfig:
    """A router like examples/router-uno.toml, with room to travel anywhere the tests go."""
    return MachineConfig(
        tick_hz=TICK_HZ,
        axes=tuple(
            AxisConfig(name="XYZA"[i], steps_per_mm=STEPS_PER_MM, max_speed=40, max_accel=500,
                       travel_min=-1000, travel_max=1000)
            for i in range(axes)
        ),
    )


def move(start_steps: tuple[int, ...], target_mm: tuple[float, ...], feed: float | None = None,
         axes: int = 3) -> list[Segment]:
    """The segments of one straight move from rest to rest, as the planner makes them."""
    config = machine_config(axes)
    program = Program(items=[LinearMove(line=1, target=target_mm, feed=feed)], lines=1)
    plan = plan_program(program, config, start_steps)
    return [plan.segments.segment(i) for i in range(len(plan))]


def along(axis: int, start_steps: tuple[int, ...], mm: float, feed: float | None = None) -> list[Segment]:
    """A move of `mm` along one axis from `start_steps`."""
    target = [s / STEPS_PER_MM for s in start_steps]
    target[axis] += mm
    return move(start_steps, tuple(target), feed, axes=len(start_steps))


def write_machine(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def events(summary: dict[str, Any], name: str | None = None) -> list[dict[str, Any]]:
    """The machine's pin changes from the emulator's exit summary (or the harness's stats)."""
    return [e for e in summary["machine"]["events"] if name is None or e["input"] == name]


def read_trace_with_carriage(path: Path) -> np.ndarray:
    """A step trace with a machine: rows of (tick, axis, direction, motor, carriage), as floats."""
    with path.open() as f:
        assert f.readline().strip() == "tick,axis,direction,motor,carriage"
        rows = np.loadtxt(f, delimiter=",", ndmin=2)
    return rows.reshape(-1, 5)
