"""`quadstep check` on a CAM-shaped pocket: what reading, planning and counting the wire bytes take.

`check` counts the bytes as an Uno is sent them (one SEGMENT a frame). The count in SEGMENTS runs
comes from the plan's arrays too (protocol/segment_run_size.py); for comparison the same count by
building and encoding every frame, as it was done before. Prints figures only.

    python3 tests/bench/bench_check.py [--lines 40000]
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
from bench_wire import machine  # noqa: E402

from quadstep.coordinates import WorkCoordinates  # noqa: E402
from quadstep.gcode import parse_gcode  # noqa: E402
from quadstep.job import UNO_RUN_LIMIT, Job  # noqa: E402
from quadstep.planner.plan import plan_program  # noqa: E402
from quadstep.protocol.frame_choice import RUN_FRAMES  # noqa: E402
from quadstep.protocol.codec import encode  # noqa: E402
from quadstep.protocol.frames import next_frame  # noqa: E402
from quadstep.protocol.messages import queue_slots  # noqa: E402
from quadstep.protocol.segment_run import RunChain  # noqa: E402


def encoded_count(job: Job) -> int:
    """Every frame built and encoded."""
    segments = job.plan.segments
    chain = RunChain(segments.axis_count)
    total = index = 0
    while index < len(segments):
        message = next_frame(segments, index, len(segments), chain, UNO_RUN_LIMIT)
        total += len(encode(message, 0))
        index += queue_slots(message)
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, default=40_000)
    args = parser.parse_args()
    text = cam_jobs.pocket(args.lines)
    config = machine("XYZ", None)
    clock = time.process_time
    began = clock()
    program = parse_gcode(text, config.axis_names, (0.0,) * 3, config.arc_tolerance, True)
    parsed = clock()
    plan = plan_program(program, config)
    planned = clock()
    job = Job(path=Path("pocket"), program=program, plan=plan, coordinates=WorkCoordinates())
    summary = job.summary()
    summed = clock()
    runs = job.wire_bytes(RUN_FRAMES)
    counted = clock()
    encoded = encoded_count(job)
    by_frames = clock() - counted
    print(
        f"pocket: {args.lines:,} lines, {plan.moves:,} moves, {len(plan):,} segments (CPU seconds)"
    )
    print(
        f"  read {parsed - began:.2f} s, plan {planned - parsed:.2f} s, "
        f"summary with the wire count {summed - planned:.2f} s: check {summed - began:.2f} s"
    )
    print(
        f"  wire bytes as an Uno is sent them {summary.wire_bytes:,}; in SEGMENTS runs {runs:,} "
        f"from the arrays in {counted - summed:.2f} s, by encoding every frame {encoded:,} in "
        f"{by_frames:.2f} s"
    )


if __name__ == "__main__":
    main()
