"""Which jobs `quadstep run` streams as they are planned, and what it says of them.

A G-code file larger than STREAM_BYTES is checked whole in one pass (job_scan.py), then planned and
sent a part at a time (machine/file_feed.py): its first move starts as soon as the check ends, and
the check's memory stays the same however long the file (the running job keeps what it was given:
docs/JOBS.md, "Large files"). Smaller files, move files, --from-line, --resume and files that
probe (G38.x) are planned whole before anything is sent.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..job import is_move_file
from ..job_scan import Scan, scan_job
from ..planner.program import JobError
from .options import CliError

# About 10 000 lines of CAM output: planned whole, such a file starts within a few seconds.
STREAM_BYTES = 256 * 1024


def streams(args: argparse.Namespace) -> bool:
    """Whether the job is checked whole, then planned and sent a part at a time."""
    path: Path = args.job
    try:
        size = path.stat().st_size
    except OSError:
        return False  # reading it says why
    return (
        size > STREAM_BYTES
        and not is_move_file(path)
        and not args.resume
        and args.from_line is None
    )


def check_file(
    args: argparse.Namespace,
    config: MachineConfig,
    start: tuple[int, ...],
    coordinates: WorkCoordinates,
) -> Scan:
    """The whole file checked from `start`, or the command's error line."""
    try:
        return scan_job(
            args.job, config, start, args.skip_unsupported, coordinates, args.feed_override
        )
    except JobError as exc:
        raise CliError(str(exc)) from None


def checked_text(path: Path, scan: Scan, feed_override: int) -> str:
    lines = f"{scan.lines} line{'s' if scan.lines != 1 else ''}"
    override = f" at feed override {feed_override} %" if feed_override != 100 else ""
    return (
        f"{path}: {lines}, {scan.moves} moves{override}; every target inside the travel; planned "
        "and sent a part at a time"
    )


def notes(scan: Scan) -> list[str]:
    """The skipped words and the lines after the program's end, as a job planned whole says
    them."""
    said = []
    if scan.skipped_count:
        words = ", ".join(f"line {line}: {word}" for line, word in scan.skipped)
        more = scan.skipped_count - len(scan.skipped)
        words += f" and {more} more" if more else ""
        plural = "s" if scan.skipped_count != 1 else ""
        said.append(f"skipped {scan.skipped_count} unsupported word{plural}: {words}")
    if scan.after_end and scan.end_line is not None:
        count = scan.after_end
        said.append(
            f"line {scan.end_line} ends the program (M2/M30): the {count} line"
            f"{'s' if count != 1 else ''} after it {'are' if count != 1 else 'is'} not run"
        )
    return said
