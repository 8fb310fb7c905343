"""Options every command shares: where the board is (--port or --emulator), and --json."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..config import MachineConfig
from ..link import DEFAULT_BAUD, PortError, auto_port
from ..machine import Machine, Target, open_machine, state_path

DEFAULT_CONFIG = Path("quadstep.toml")


class CliError(Exception):
    """Bad input from the command line or a file: printed as one clear message, exit code 1."""


def add_connection_options(parser: argparse.ArgumentParser) -> None:
    """--port PORT | --emulator [--sim FILE.toml], and --baud, --free, --trace."""
    where = parser.add_mutually_exclusive_group(required=False)
    where.add_argument(
        "--port",
        metavar="PORT",
        help="serial port of the board (/dev/ttyUSB0, socket://host:port), "
        "or auto: the one Uno, Mega or clone on USB (the default without --emulator)",
    )
    where.add_argument(
        "--emulator", action="store_true", help="start the loopback emulator and use it"
    )
    parser.add_argument(
        "--sim",
        type=Path,
        metavar="FILE.toml",
        help="the emulator (implied) with this simulated machine around its motors: switches, "
        "probe, backlash (docs/SIMULATED_MACHINE.md)",
    )
    parser.add_argument(
        "--baud", type=baud_rate, default=DEFAULT_BAUD, help=f"baud rate (default {DEFAULT_BAUD})"
    )
    parser.add_argument(
        "--free", action="store_true", help="with --emulator: run ticks as fast as possible"
    )
    parser.add_argument(
        "--trace", type=Path, metavar="CSV", help="with --emulator: write every step to CSV"
    )


def baud_rate(text: str) -> int:
    """--baud: a whole number of bits per second, 300 … 4,000,000."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 300 <= value <= 4_000_000:
        raise argparse.ArgumentTypeError(f"{value} is outside 300 … 4000000")
    return value


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of text")


def target(args: argparse.Namespace) -> Target:
    """The machine the arguments name: --port PORT, or --emulator (with --free, --trace, --sim)."""
    emulator = args.emulator or args.sim is not None
    if args.port is not None and args.sim is not None:
        raise CliError("--sim runs the emulator: give it without --port")
    if (args.port is None and not emulator) or args.port == "auto":
        try:
            args.port = auto_port()
        except PortError as exc:
            raise CliError(
                f"{exc}" if args.port == "auto" else f"{exc}; --emulator runs without a board"
            ) from None
    if (
        args.port is not None
        and args.port.startswith("socket://")
        and not args.port[9:].rpartition(":")[2].isdigit()
    ):
        raise CliError(
            f"--port {args.port}: a TCP port is socket://HOST:PORT, with the port number"
        )
    if not emulator and (args.free or args.trace):
        raise CliError("--free and --trace apply only with --emulator")
    options: dict[str, object] = {"free": args.free, "trace": args.trace} if emulator else {}
    if args.sim is not None:
        if not args.sim.is_file():
            raise CliError(f"--sim {args.sim}: no such file")
        options["extra_args"] = ["--machine", str(args.sim)]
    return Target(port=args.port, emulator=emulator, baud=args.baud, emulator_options=options)


def config_path(args: argparse.Namespace) -> Path | None:
    """The configuration file the commands read (None: the default machine, there being none)."""
    if args.config is not None:
        return args.config
    return DEFAULT_CONFIG if DEFAULT_CONFIG.exists() else None


def connect(
    args: argparse.Namespace,
    config: MachineConfig | None = None,
    source: str = "",
    state_file: Path | None = None,
) -> Machine:
    """The connected Machine the arguments ask for (a context manager); an emulator started for it
    ticks and has the axes that `config` says. With a configuration, the machine's state is kept in
    its state file (`state_file`, else the configuration's: machine/state.py), held by this process
    alone; what connecting found of it (a board reset since the last command) goes to stderr."""
    if config is not None and state_file is None:
        state_file = state_path(config_path(args))
    machine = open_machine(
        target(args), config, source=source or "the configuration", state_file=state_file
    )
    if machine.notice is not None:
        print(machine.notice, file=sys.stderr, flush=True)
    return machine
