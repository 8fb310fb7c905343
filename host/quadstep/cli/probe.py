"""`quadstep probe`: G38.2–G38.5 from the command line: move until the probe touches (or lets go)
and print the exact latched position."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..machine.probing import CODES, probe
from ._jobs import machine_config
from ._stops import interrupted
from .options import CliError, add_connection_options, add_json_option, connect


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "probe", help="G38.2–G38.5: move until the probe touches or lets go"
    )
    parser.add_argument(
        "target",
        nargs="+",
        metavar="AXIS=MM",
        help="where to move at most (machine mm), e.g. Z=-30",
    )
    parser.add_argument("--feed", type=float, default=1.0, help="mm/s (default 1)")
    parser.add_argument(
        "--mode",
        choices=sorted(CODES),
        default="38.2",
        help="38.2 toward, error if no contact (default); 38.3 toward; 38.4 away, error if "
        "contact stays; 38.5 away",
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
    with connect(args, config, str(args.config or "quadstep.toml")) as machine:
        target = list(machine.position_mm)
        for word in args.target:
            name, sep, value = word.partition("=")
            if not sep or name.upper() not in config.axis_names:
                raise CliError(
                    f"{word!r}: give AXIS=MM with an axis of {', '.join(config.axis_names)}"
                )
            try:
                target[config.axis_names.index(name.upper())] = float(value)
            except ValueError:
                raise CliError(f"{word!r}: {value!r} is not a number of mm") from None
        try:
            result = probe(machine, args.mode, target, args.feed)
        except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP
            return interrupted(args, machine, exc)
    if args.json:
        print(json.dumps(result.__dict__))
    else:
        where = "  ".join(f"{a.name} {x:.4f}" for a, x in zip(config.axes, result.machine_mm))
        print(
            f"G{result.code}: {'contact at' if result.found else 'no contact, at rest at'} {where} "
            f"mm (steps {list(result.steps)})"
        )
    return 0 if result.found or args.mode in ("38.3", "38.5") else 1
