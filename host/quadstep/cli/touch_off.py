"""`quadstep touch-off z|edge|corner|bore|boss`: the touch-off routines (machine/touch_off.py) from
the command line; each sets the active work zero and prints it."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..machine.touch_off import TouchOff
from ._jobs import machine_config
from ._stops import interrupted
from .options import CliError, add_connection_options, connect

KINDS = ("z", "edge", "corner", "bore", "boss")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "touch-off", help="probe Z on a plate, an edge, a corner, a bore or a boss: set work zero"
    )
    parser.add_argument(
        "kind",
        choices=KINDS,
        help="what to find: z (the surface under a plate), an edge, a corner, a bore's or a boss's "
        "centre",
    )
    parser.add_argument(
        "where",
        nargs="?",
        default="",
        help="edge: the axis and the way toward the face (X+, Y-); corner: both (X+Y-); "
        "boss: its size across in mm",
    )
    parser.add_argument(
        "--plate",
        type=float,
        metavar="MM",
        help="the plate's thickness in mm (default: [touch_off] in the configuration)",
    )
    parser.add_argument("--config", type=Path, metavar="FILE", help="machine configuration")
    add_connection_options(parser)
    parser.set_defaults(handler=run)


def _direction(word: str, axis: str) -> int:
    at = word.upper().find(axis)
    if at < 0 or at + 1 >= len(word) or word[at + 1] not in "+-":
        raise CliError(f"{word!r}: give {axis}+ or {axis}- (the way toward the face)")
    return 1 if word[at + 1] == "+" else -1


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    with connect(args, config, str(args.config or "quadstep.toml")) as machine:
        touch = TouchOff(machine, machine.config.touch_off, print)
        try:
            if args.kind == "z":
                result = touch.z(args.plate)
            elif args.kind == "edge":
                axis = args.where[:1].upper()
                result = touch.edge(axis, _direction(args.where, axis))
            elif args.kind == "corner":
                x, y = _direction(args.where, "X"), _direction(args.where, "Y")
                result = touch.corner(x, y)
            elif args.kind == "bore":
                result = touch.bore()
            else:
                try:
                    result = touch.boss(float(args.where))
                except ValueError:
                    raise CliError(f"boss {args.where!r}: give its size across in mm") from None
        except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP
            return interrupted(args, machine, exc)
    print(result.describe())
    return 0
