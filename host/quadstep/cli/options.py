"""Options every command shares: where the board is (--port or --emulator), and --json."""

from __future__ import annotations

import argparse
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ..config import error_location
from ..emulator import open_connection
from ..link import DEFAULT_BAUD, Link


class CliError(Exception):
    """Bad input from the command line or a file: printed as one clear message, exit code 1."""


def add_connection_options(parser: argparse.ArgumentParser) -> None:
    """--port PORT | --emulator, and --baud, --free, --trace."""
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--port", metavar="PORT", help="serial port of the board (/dev/ttyACM0, socket://host:port)")
    where.add_argument("--emulator", action="store_true", help="start the loopback emulator and use it")
    parser.add_argument("--baud", type=int, default=DEFAULT_BAUD, help=f"baud rate (default {DEFAULT_BAUD})")
    parser.add_argument("--free", action="store_true", help="with --emulator: run ticks as fast as possible")
    parser.add_argument("--trace", type=Path, metavar="CSV", help="with --emulator: write every step to CSV")


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of text")


def connect(args: argparse.Namespace, **emulator_options: Any) -> AbstractContextManager[Link]:
    """The connected Link the arguments ask for; `emulator_options` go to Emulator (e.g. tick_hz)."""
    if not args.emulator and (args.free or args.trace):
        raise CliError("--free and --trace apply only with --emulator")
    if args.emulator:
        emulator_options.setdefault("free", args.free)
        emulator_options.setdefault("trace", args.trace)
    return open_connection(args.port, args.emulator, baudrate=args.baud, **(emulator_options if args.emulator else {}))


def _location(loc: tuple[int | str, ...]) -> str:
    return error_location(loc) or "(top level)"


def format_validation_error(error: ValidationError, source: str = "") -> str:
    """One line per problem: where (e.g. segments[3].axes[0].v0), what is wrong, and the value given."""
    lines = []
    for e in error.errors():
        where = _location(tuple(e["loc"]))
        message = e["msg"].removeprefix("Value error, ")
        scalar = isinstance(e["input"], (int, float, str)) and e["type"] != "missing"
        given = f" (got {e['input']!r})" if scalar else ""
        lines.append(f"{source}{': ' if source else ''}{where}: {message}{given}")
    return "\n".join(lines)
