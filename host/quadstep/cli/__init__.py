"""The `quadstep` command line.

Each module of this package that defines `register(subparsers)` adds one
subcommand: it creates its parser with `subparsers.add_parser(...)` and sets
`handler=` (a function taking the parsed arguments and returning an exit
code) with `set_defaults`. New commands are new files; nothing here changes.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
from importlib import metadata
import sys
from collections.abc import Sequence

from pydantic import ValidationError

from .. import __version__
from ..config import describe_validation_error
from ..emulator import EmulatorError
from ..link import LinkError
from ..machine import MachineError, StateError
from .options import CliError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="quadstep", description="Exact quadratic stepper motion over serial.")
    parser.add_argument("--version", action="version", version=f"quadstep {version()}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if module.name.startswith("_"):
            continue
        command = importlib.import_module(f"{__name__}.{module.name}")
        register = getattr(command, "register", None)
        if callable(register):
            register(subparsers)
    return parser


def version() -> str:
    """The installed package's version (pyproject.toml), or the source tree's when it is not installed."""
    try:
        return metadata.version("quadstep")
    except metadata.PackageNotFoundError:
        return __version__


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except CliError as exc:
        print(f"quadstep {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except ValidationError as exc:
        print(f"quadstep {args.command}: error: {'; '.join(describe_validation_error(exc))}", file=sys.stderr)
        return 1
    except (LinkError, MachineError, StateError, EmulatorError) as exc:
        print(f"quadstep {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"quadstep {args.command}: interrupted", file=sys.stderr)
        return 130
