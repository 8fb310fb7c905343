"""`quadstep backlash measure --axis X [--method probe|switch]`, `quadstep backlash calibrate-switch
--axis X`.

The measurement runs on the machine (docs/BACKLASH.md); its result is written to the configuration
file only after the user confirms (--write; --yes confirms beforehand), comments kept and the old
file kept as .bak.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..config import ConfigError
from ._jobs import config_path, machine_config
from ._stops import interrupted
from .options import CliError, add_connection_options, add_json_option, connect


def _direction(text: str) -> int:
    if text not in ("+", "-"):
        raise argparse.ArgumentTypeError("give + or -")
    return 1 if text == "+" else -1


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "backlash", help="measure an axis's backlash (probe or switch) and keep it"
    )
    commands = parser.add_subparsers(dest="backlash_command", metavar="ACTION", required=True)
    measure = commands.add_parser("measure", help="measure the backlash of one axis, k times")
    calibrate = commands.add_parser(
        "calibrate-switch",
        help="find a limit switch's own hysteresis, the backlash being known, for --method switch",
    )
    for p in (measure, calibrate):
        p.add_argument("--axis", required=True, metavar="AXIS", help="X, Y, Z or A")
        p.add_argument(
            "--config",
            type=Path,
            metavar="FILE",
            help="machine configuration (default ./quadstep.toml)",
        )
        p.add_argument("--tries", type=int, default=5, metavar="K", help="tries (default 5)")
        p.add_argument(
            "--end",
            choices=("min", "max"),
            help="switch: which end's switch (default: the homing end)",
        )
        p.add_argument(
            "--write",
            action="store_true",
            help="write the result to the configuration (asks first)",
        )
        p.add_argument("--yes", action="store_true", help="with --write: do not ask")
        add_connection_options(p)
        add_json_option(p)
    measure.add_argument(
        "--method",
        choices=("probe", "switch"),
        default="probe",
        help="probe: touch a face, then a neighbouring one to check; switch: the axis's limit "
        "switch (default probe; docs/BACKLASH.md)",
    )
    measure.add_argument(
        "--toward",
        type=_direction,
        default=None,
        metavar="+|-",
        help="probe: the axis's direction toward the face it touches (default + for X/Y, - for Z)",
    )
    measure.add_argument(
        "--test-axis",
        metavar="AXIS",
        help="probe: the axis that checks the neighbouring face (default Y for X, X otherwise)",
    )
    measure.add_argument(
        "--test-toward",
        type=_direction,
        default=1,
        metavar="+|-",
        help="probe: the test axis's direction toward that face (default +)",
    )
    measure.add_argument(
        "--search",
        type=float,
        default=None,
        metavar="MM",
        help="farthest approach (default 10 mm probe, 5 mm switch)",
    )
    measure.add_argument(
        "--clear",
        type=float,
        default=3.0,
        metavar="MM",
        help="probe: how far the test axis backs away from its face (default 3)",
    )
    measure.add_argument(
        "--max",
        type=float,
        default=1.0,
        metavar="MM",
        help="largest backlash looked for (default 1)",
    )
    measure.add_argument(
        "--feed",
        type=float,
        default=None,
        metavar="MM/S",
        help="approach speed (default 2 probe, 1 switch)",
    )
    measure.add_argument(
        "--max-spread",
        type=float,
        default=0.01,
        metavar="MM",
        help="refuse a result whose tries spread more (default 0.01)",
    )
    calibrate.add_argument(
        "--backlash",
        type=float,
        default=None,
        metavar="MM",
        help="the axis's backlash (default: the configuration's, as measured)",
    )
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..machine.backlash import (
        MeasureError,  # here: every command's parser is built at each start
    )

    config = machine_config(args)
    name = args.axis.upper()
    if name not in config.axis_names:
        raise CliError(
            f"--axis {args.axis}: not an axis of the configuration ({', '.join(config.axis_names)})"
        )
    if args.tries < 1:
        raise CliError(f"--tries {args.tries}: must be at least 1")
    say = (
        (lambda text: None)
        if args.json
        else (lambda text: print(text, file=sys.stderr, flush=True))
    )
    try:
        with connect(args, config, str(config_path(args) or "the default machine")) as machine:
            try:
                if args.backlash_command == "calibrate-switch":
                    return _calibrate(args, machine, name, say)
                result = _measure(args, machine, name, say)
            except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM, SIGHUP
                return interrupted(args, machine, exc)
    except MeasureError as exc:
        raise CliError(str(exc)) from None
    if args.json:
        print(json.dumps(result.as_dict()))
    else:
        print(
            f"{name} backlash: {result.mm:.4f} mm ({result.steps:g} steps, {result.whole_steps} "
            f"whole), spread {result.spread_steps:g} steps ({result.spread_mm:.4f} mm) over "
            f"{len(result.tries)} tries"
        )
    if not result.accepted:
        print(f"refused: {result.refused}", file=sys.stderr)
        return 1
    if args.write:
        _write(args, name, f"backlash.mm = {result.mm:.4f}", mm=result.mm)
    return 0


def _measure(args: argparse.Namespace, machine, name: str, say):
    from ..machine.backlash import PROBE_SETUP, measure_with_probe, measure_with_switch

    if args.method == "switch":
        return measure_with_switch(
            machine,
            name,
            end=args.end,
            tries=args.tries,
            search=args.search or 5.0,
            feed=args.feed or 1.0,
            max_spread=args.max_spread,
            on_progress=say,
        )
    toward, test = PROBE_SETUP[name]
    toward = args.toward if args.toward is not None else toward
    return measure_with_probe(
        machine,
        name,
        toward=toward,
        test=(args.test_axis or test).upper(),
        test_toward=args.test_toward,
        tries=args.tries,
        search=args.search or 10.0,
        clear=args.clear,
        largest=args.max,
        feed=args.feed or 2.0,
        max_spread=args.max_spread,
        on_progress=say,
    )


def _calibrate(args: argparse.Namespace, machine, name: str, say) -> int:
    from ..machine.backlash import calibrate_switch, known_backlash

    known = known_backlash(machine.config, name, args.backlash)
    hysteresis = calibrate_switch(
        machine, name, known, end=args.end, tries=args.tries, on_progress=say
    )
    if args.json:
        print(json.dumps({"axis": name, "backlash_mm": known, "switch_hysteresis_mm": hysteresis}))
    else:
        print(f"{name} switch hysteresis: {hysteresis:.4f} mm (backlash {known:.4f} mm taken off)")
    if args.write:
        _write(
            args,
            name,
            f"backlash.switch_hysteresis = {hysteresis:.4f}",
            switch_hysteresis=hysteresis,
        )
    return 0


def _write(args: argparse.Namespace, name: str, what: str, **values: float) -> None:
    from ..config_file import set_backlash

    path = config_path(args)
    if path is None:
        raise CliError("no configuration file to write the backlash to: give --config FILE")
    if not args.yes:
        print(f"write {name} {what} to {path}? [y/N] ", end="", file=sys.stderr, flush=True)
        if sys.stdin.readline().strip().lower() not in ("y", "yes"):
            print("not written", file=sys.stderr)
            return
    try:
        _, backup = set_backlash(path, name, **values)
    except (ConfigError, OSError) as exc:
        raise CliError(str(exc)) from None
    print(f"wrote {path} ({name} {what}; the old file is {backup})", file=sys.stderr)
