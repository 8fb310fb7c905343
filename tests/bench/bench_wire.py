"""Wire benchmark: bytes on the serial line against the G-code's own bytes, for three CAM-shaped jobs.

The jobs come from tests/bench/cam_jobs.py (a 40,000-line pocket, a 16,000-line engraving, a 51,000-line
four-axis job). Byte counts are exact (every frame as the link frames it). Also printed: what the same plans
would take if a segment that continues the one before carried only its end speeds and runs of equal cruises
were one cubic segment (an estimate: no such frame exists yet). Nothing is asserted.

    python3 tests/bench/bench_wire.py [--scurve]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import cam_jobs  # noqa: E402

from quadstep.config import MachineConfig, parse_config  # noqa: E402
from quadstep.coordinates import WorkCoordinates  # noqa: E402
from quadstep.gcode import parse_gcode  # noqa: E402
from quadstep.job import Job  # noqa: E402
from quadstep.planner.plan import Plan, plan_program  # noqa: E402
from quadstep.planner.segments import SegmentArrays  # noqa: E402

FRAME = 6  # type, seq, CRC-16, COBS code byte, delimiter


def machine(names: str, jerk: float | None) -> MachineConfig:
    """A router at 400 steps/mm (A: 3200 steps per turn), at 32 kHz as the Uno."""
    axes = []
    for n in names:
        spm = 400.0 if n != "A" else 3200 / 360
        axis = {"name": n, "steps_per_mm": spm, "max_speed": 40.0 if n != "A" else 2000.0,
                "max_accel": 500.0 if n != "A" else 5000.0, "travel_min": -400.0, "travel_max": 400.0}
        if n == "A":
            axis.update(travel_min=-100000.0, travel_max=100000.0)
        if jerk is not None:
            axis["max_jerk"] = jerk if n != "A" else jerk * 20
        axes.append(axis)
    return parse_config({"tick_hz": 32000, "axes": axes})


def chained_estimate(plan: Plan) -> int:
    """Bytes if continuing segments carried only vn per axis and equal cruises ran as one segment."""
    segments = plan.segments
    assert isinstance(segments, SegmentArrays)
    a = segments.numpy()
    axes, v0, vn = a["axes"].astype(np.int64), a["v0"], a["vn"]
    k = np.array([bin(x & 15).count("1") for x in axes])
    chained = np.zeros(len(segments), dtype=bool)
    chained[1:] = (axes[1:] == axes[:-1]) & np.all(v0[1:] == vn[:-1], axis=1)
    cruise = chained & np.all(v0 == vn, axis=1)
    merged = np.zeros(len(segments), dtype=bool)
    merged[1:] = cruise[1:] & cruise[:-1] & np.all(v0[1:] == v0[:-1], axis=1)
    size = np.where(cruise, 3 + FRAME, np.where(chained, 3 + 2 * k + FRAME, 3 + 6 * k + FRAME))
    return int(size[~merged].sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scurve", action="store_true", help="also plan with max_jerk (slow: minutes)")
    args = parser.parse_args()
    print("| job | G-code | moves | planner | segments | bytes on the wire | wire / G-code |")
    print("|---|---|---|---|---|---|---|")
    for name, make in cam_jobs.JOBS.items():
        text = make()
        names = "XYZA" if name == "four_axis" else "XYZ"
        gcode = len(text.encode())
        lines = text.count("\n")
        for jerk in (None, 20000.0) if args.scurve else (None,):
            config = machine(names, jerk)
            program = parse_gcode(text, config.axis_names, (0.0,) * len(names), config.arc_tolerance, True)
            began = time.perf_counter()
            plan = plan_program(program, config)
            seconds = time.perf_counter() - began
            wire = Job(path=Path(name), program=program, plan=plan, coordinates=WorkCoordinates()).wire_bytes()
            kind = "S-curve" if jerk else "constant acceleration"
            print(f"| {name} | {lines:,} lines, {gcode:,} B | {plan.moves:,} | {kind} ({seconds:.0f} s) | "
                  f"{len(plan):,} | {wire:,} | {wire / gcode:.2f} |")
            if jerk is None:
                estimate = chained_estimate(plan)
                print(f"| {name} | | | chained frames (estimate) | | {estimate:,} | {estimate / gcode:.2f} |")


if __name__ == "__main__":
    main()
