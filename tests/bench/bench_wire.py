"""Wire benchmark: bytes on the serial line against the G-code's own bytes, for three CAM-shaped jobs.

The jobs come from tests/bench/cam_jobs.py (a 40,000-line pocket, a 16,000-line engraving, a 51,000-line
four-axis job). Byte counts are exact: every frame as a motion sends it in runs (SEGMENTS or, with --scurve,
CUBIC_SEGMENTS frames of up to 7 chained segments, PROTOCOL.md §5.2), as to the emulator; beside one segment
a frame (a board without runs, or a noisy line); and what an Uno is sent (one SEGMENT a frame, which it takes
faster than SEGMENTS, but CUBIC_SEGMENTS runs: protocol/frame_choice.py).
Nothing is asserted.

    python3 tests/bench/bench_wire.py [--scurve]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "host"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import cam_jobs  # noqa: E402

from quadstep.config import MachineConfig, parse_config  # noqa: E402
from quadstep.coordinates import WorkCoordinates  # noqa: E402
from quadstep.gcode import parse_gcode  # noqa: E402
from quadstep.job import Job  # noqa: E402
from quadstep.planner.plan import plan_program  # noqa: E402
from quadstep.protocol.frame_choice import AVR_FRAMES, RUN_FRAMES, SINGLE_FRAMES  # noqa: E402

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scurve", action="store_true", help="also plan with max_jerk (slow: minutes)")
    args = parser.parse_args()
    print("| job | G-code | moves | planner | segments | bytes on the wire in runs | wire / G-code | "
          "one segment a frame | as an Uno is sent |")
    print("|---|---|---|---|---|---|---|---|---|")
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
            job = Job(path=Path(name), program=program, plan=plan, coordinates=WorkCoordinates())
            wire, single = job.wire_bytes(RUN_FRAMES), job.wire_bytes(SINGLE_FRAMES)
            uno = job.wire_bytes(AVR_FRAMES)
            kind = "S-curve" if jerk else "constant acceleration"
            print(f"| {name} | {lines:,} lines, {gcode:,} B | {plan.moves:,} | {kind} ({seconds:.0f} s) | "
                  f"{len(plan):,} | {wire:,} | {wire / gcode:.2f} | {single / gcode:.2f} | {uno / gcode:.2f} |")


if __name__ == "__main__":
    main()
