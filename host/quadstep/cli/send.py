"""`quadstep send FILE.json`: stream a file of raw segments (format in docs/HOST.md)."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, model_validator

from ..protocol import AXIS_NAMES, IdentifyReply, Segment
from ..protocol.fields import I32
from ..textfile import parse_nested, read_text, strict_json
from ..validation import validate
from .options import CliError, add_connection_options, add_json_option, connect

GCODE_LINE = re.compile(r"^\s*(?:[Nn]\d+\s*)?[GgMm]\s*\d", re.MULTILINE)


class SegmentsFile(BaseModel):
    """A raw job: optional start positions (steps, one per axis from X), then segments in order."""

    model_config = ConfigDict(extra="forbid")

    positions: list[I32] | None = Field(default=None, min_length=1, max_length=4)
    segments: list[Segment] = Field(min_length=1)

    @model_validator(mode="before")
    @classmethod
    def _whole_numbers_only(cls, data: Any) -> Any:
        """Every value of the file is a whole number: never a string, a boolean or a fraction taken
        for one."""

        def check(value: Any, where: str) -> None:
            if isinstance(value, dict):
                for key, item in value.items():
                    check(item, f"{where}.{key}" if where else str(key))
            elif isinstance(value, list):
                for i, item in enumerate(value):
                    check(item, f"{where}[{i}]")
            elif isinstance(value, bool) or not isinstance(value, int):
                raise ValueError(f"{where} = {value!r}: must be a whole number")

        check(data, "")
        return data


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("send", help="stream a JSON file of raw segments")
    parser.add_argument(
        "file",
        type=Path,
        metavar="FILE.json",
        help='raw segments as JSON (docs/HOST.md, "Raw segment files")',
    )
    add_connection_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def load(path: Path) -> SegmentsFile:
    """Read and validate the whole file; every problem names its place, the limit and the value."""
    text = read_text(path, CliError)
    try:
        data = parse_nested(strict_json, text, path, CliError)
    except json.JSONDecodeError as exc:
        if GCODE_LINE.search(text):
            raise CliError(
                f"{path} is G-code: `quadstep run {path}` runs it (send streams a JSON file of raw "
                "segments, docs/HOST.md)"
            ) from None
        raise CliError(f"{path}: line {exc.lineno} column {exc.colno}: {exc.msg}") from None
    # whole numbers only: _whole_numbers_only
    job = validate(SegmentsFile, data, str(path), CliError, strict=False)
    last = job.segments[-1]
    moving = [a.axis for a in last.axes if a.vn > 0]
    if moving:
        raise CliError(
            f"{path}: segments[{len(job.segments) - 1}]: the last segment must end at rest, but "
            f"axis {moving[0]} ends at vn > 0 (the firmware would brake to rest on its own: "
            "STARVED)"
        )
    return job


def check_against(job: SegmentsFile, ident: IdentifyReply, path: Path) -> None:
    """Refuse, before anything is sent, what this firmware cannot run."""
    if job.positions is not None and len(job.positions) > ident.axis_count:
        raise CliError(
            f"{path}: positions has {len(job.positions)} values, the firmware has "
            f"{ident.axis_count} axes"
        )
    for i, seg in enumerate(job.segments):
        if seg.n > ident.n_max:
            raise CliError(
                f"{path}: segments[{i}].n: {seg.n} exceeds the firmware's n_max {ident.n_max}"
            )
        for j, move in enumerate(seg.axes):
            if move.axis >= ident.axis_count:
                raise CliError(
                    f"{path}: segments[{i}].axes[{j}].axis: {move.axis}, the firmware has axes "
                    f"0..{ident.axis_count - 1}"
                )


def run(args: argparse.Namespace) -> int:
    job = load(args.file)
    with connect(args) as machine:
        check_against(job, machine.identity, args.file)
        if job.positions is not None:
            machine.set_position(dict(enumerate(job.positions)))
        start = machine.status()
        motion = machine.send_segments(job.segments)
        if not args.json:
            print(f"{args.file}: sending {len(job.segments)} segments", flush=True)
        try:
            while motion.wait(0.1) is None:
                pass
        except KeyboardInterrupt:
            end = machine.hold("interrupt")
            print(f"stopped (HOLD) at positions {list(end.position) if end is not None else '?'}")
            return 130
        end = motion.wait()
        assert end is not None
        if end.error:
            raise CliError(end.error)
        final = machine.status()
    ticks = final.motion_ticks - start.motion_ticks
    if args.json:
        print(
            json.dumps(
                {
                    "positions": list(final.position),
                    "segments": len(job.segments),
                    "motion_ticks": ticks,
                    "link": machine.stats.as_dict(),
                }
            )
        )
    else:
        names = "  ".join(f"{AXIS_NAMES[i]} {p}" for i, p in enumerate(final.position))
        print(f"sent {len(job.segments)} segments, {ticks} ticks of motion")
        print(f"positions (steps): {names}")
    return 0
