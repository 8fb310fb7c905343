"""`quadstep check JOB`: read, check and plan a job without a machine; print what it would do."""

from __future__ import annotations

import argparse

from ._jobs import add_job_options, format_duration, job_from_args, machine_config, skipped_text, stored_coordinates
from .options import add_json_option


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("check", help="validate and plan a job; print moves, distance, duration, speeds")
    add_job_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    job = job_from_args(args, config, coordinates=stored_coordinates(args))  # from the machine origin
    summary = job.summary()
    if args.json:
        print(summary.model_dump_json())
        return 0
    print(
        f"{summary.file}: {job.source_size}, {summary.moves} moves, {summary.segments} segments "
        f"({summary.wire_bytes / 1000:.1f} kB on the wire)"
    )
    print(f"distance {summary.distance_mm:.1f} mm, planned duration {format_duration(summary.duration_s)}")
    print(f"axis   peak speed     work ({job.coordinates.name} → {summary.work_system})    machine")
    for axis in summary.axes:
        print(
            f"{axis.name:<6} {axis.peak_speed:7.2f} mm/s   {axis.start_work_mm:.3f} → {axis.end_work_mm:.3f} mm"
            f"   {axis.start_mm:.3f} → {axis.end_mm:.3f} mm ({axis.end_steps} steps)"
        )
    if summary.pauses:
        print(f"pauses for the operator at line{'s' if len(summary.pauses) > 1 else ''} "
              f"{', '.join(map(str, summary.pauses))}")
    skipped = skipped_text(job)
    if skipped:
        print(skipped)
    return 0
