"""`quadstep home`: find machine zero with the homing switches (the GRBL cycle, from exact
latches)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..machine.homing import home
from ._jobs import machine_config
from ._stops import interrupted
from .options import add_connection_options, add_json_option, connect


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "home", help="home the machine: find each axis's switch and set machine zero"
    )
    parser.add_argument(
        "axes",
        nargs="*",
        metavar="AXIS",
        help="axes to home (default: every axis with [axes.homing], in the configured order)",
    )
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="machine configuration (default ./quadstep.toml)",
    )
    add_connection_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)

    def progress(text: str) -> None:
        if not args.json:
            print(text, file=sys.stderr, flush=True)

    with connect(args, config, str(args.config or "quadstep.toml")) as machine:
        try:
            results = home(machine, args.axes or None, progress)
        except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP
            return interrupted(args, machine, exc)
        position = machine.position_mm
    if args.json:
        print(json.dumps({"axes": [r.__dict__ for r in results], "position_mm": list(position)}))
    else:
        print("homed: " + "  ".join(f"{r.name} {r.position_mm:.3f} mm" for r in results))
    return 0
