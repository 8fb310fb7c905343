"""The `quadstep` command line.

Each module of this package that defines `register(subparsers)` adds one
subcommand: it creates its parser with `subparsers.add_parser(...)` and sets
`handler=` (a function taking the parsed arguments and returning an exit
code) with `set_defaults`. New commands are new files; nothing here changes.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
from collections.abc import Sequence
from importlib import metadata

from .. import __version__
from ._stops import INTERRUPTED, stop_signals_as_interrupt, why


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="quadstep", description="Exact quadratic stepper motion over serial."
    )
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
    """The installed package's version (pyproject.toml), or the source tree's when it is not
    installed."""
    try:
        return metadata.version("quadstep")
    except metadata.PackageNotFoundError:
        return __version__


def main(argv: Sequence[str] | None = None) -> int:
    """Run a command. Ctrl-C, SIGTERM and SIGHUP at any moment, loading included, are a controlled
    stop: one line and exit code 130 (a command that moves the machine brings it to rest first and
    says where)."""
    name = "quadstep"
    try:
        with stop_signals_as_interrupt():
            args = build_parser().parse_args(argv)
            name = f"quadstep {args.command}"
            from ._errors import run_command  # the package's errors, loaded with the commands

            code = run_command(args)
            sys.stdout.flush()  # a closed pipe (`| head`) shows here, not at the interpreter's exit
            return code
    except KeyboardInterrupt as exc:
        print(f"{name}: interrupted{why(exc)}", file=sys.stderr)
        return INTERRUPTED
    except BrokenPipeError:
        quiet_stdout()
        return 141  # as a shell reports a command ended by SIGPIPE


def quiet_stdout() -> None:
    """Whoever read stdout has gone: what is still buffered goes nowhere, without a second error at
    exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass  # stdout is no file (captured in-process)
