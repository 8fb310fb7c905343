"""`quadstep check JOB`: read, check and plan a job without a machine; print what it would do."""

from __future__ import annotations

import argparse
import json

from ..config import MachineConfig
from ..job import Job
from ..planner.plan import Plan
from ..planner.raster_gcode import plan_with_rasters
from ..toolpath import Box, toolpath
from ._jobs import (
    add_job_options,
    after_end_text,
    approach_text,
    format_duration,
    job_from_args,
    machine_config,
    skipped_text,
    stored_coordinates,
)
from .options import add_json_option


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "check", help="validate and plan a job; print moves, distance, duration, speeds"
    )
    add_job_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    # from the machine origin
    job = job_from_args(args, config, coordinates=stored_coordinates(args))
    summary = job.summary()
    path = toolpath(job.program, config.to_mm(job.plan.start))
    names = config.axis_names
    rows = _as_rows(job, config)
    if args.json:
        data = summary.model_dump()
        data["rasters"] = (
            None if rows is None else {"segments": len(rows), "duration_s": rows.duration_s}
        )
        data["bounds"] = {
            kind: _box_json(names, box)
            for kind, box in (("work", path.work_box), ("machine", path.machine_box))
        }
        if job.approach is not None:
            data["approach"] = approach_text(job)
        print(json.dumps(data))
        return 0
    print(
        f"{summary.file}: {job.source_size}, {summary.moves} moves, {summary.segments} segments "
        f"({summary.wire_bytes / 1000:.1f} kB on the wire)"
    )
    print(
        f"distance {summary.distance_mm:.1f} mm, planned duration "
        f"{format_duration(summary.duration_s)}"
    )
    if rows is not None:
        print(
            f"on a board with RASTER (the Mega, the emulator, the Uno's laser build), its laser "
            f"rasters as rows at one speed each: {len(rows)} segments, planned duration "
            f"{format_duration(rows.duration_s)}"
        )
    print(f"axis   peak speed     work ({job.coordinates.name} → {summary.work_system})    machine")
    for axis in summary.axes:
        print(
            f"{axis.name:<6} {axis.peak_speed:7.2f} mm/s   {axis.start_work_mm:.3f} → "
            f"{axis.end_work_mm:.3f} mm   {axis.start_mm:.3f} → {axis.end_mm:.3f} mm "
            f"({axis.end_steps} steps)"
        )
    if path.machine_box is not None and path.work_box is not None:
        print(f"bounding box   work     {_box_text(names, path.work_box)}")
        print(f"               machine  {_box_text(names, path.machine_box)}")
        print(f"{path.cuts} cuts, {path.rapids} rapids")
    if summary.pauses:
        print(
            f"pauses for the operator at line{'s' if len(summary.pauses) > 1 else ''} "
            f"{', '.join(map(str, summary.pauses))}"
        )
    for note in (skipped_text(job), after_end_text(job)):
        if note:
            print(note)
    if job.approach is not None:
        print(approach_text(job))
    return 0


def _as_rows(job: Job, config: MachineConfig) -> Plan | None:
    """The plan a board with RASTER runs, the job's laser rasters as rows of RASTER lines (as
    `quadstep run` sends them); None where it has none or runs at a feed override."""
    if job.feed_override != 100:
        return None
    return plan_with_rasters(job.program, config, job.plan.start)


def _box_text(names: tuple[str, ...], box: Box) -> str:
    return "  ".join(f"{n} {lo:.3f} … {hi:.3f}" for n, lo, hi in zip(names, box.low, box.high))


def _box_json(names: tuple[str, ...], box: Box | None) -> dict[str, list[float]] | None:
    return None if box is None else {n: [lo, hi] for n, lo, hi in zip(names, box.low, box.high)}
