"""`quadstep tui (--port PORT | --emulator) [--config FILE]`: jog, zero and run jobs in the
terminal."""

from __future__ import annotations

import argparse
import os
import select
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

from pydantic import ValidationError

from ..config import ConfigError, load_config
from ..jog import JogSettings
from ..machine import Target, state_path
from ..validation import describe_validation_error
from ._jobs import DEFAULT_CONFIG
from ._stops import stop_signals_handled
from .options import CliError, add_connection_options, target
from .run import position_lines

if TYPE_CHECKING:
    from ..tui import QuadstepApp
    from ..tui.session import Parting  # Textual loads only for this command


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("tui", help="terminal user interface: positions, jogging, jobs")
    add_connection_options(parser)
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help=f"machine configuration (TOML; default ./{DEFAULT_CONFIG} if present, else the "
        "router of examples/router-uno.toml, 400 steps/mm, when the firmware is the 32 kHz 3-axis "
        "one it describes, or a generic machine at 80 steps/mm, travel ±1000 mm)",
    )
    parser.add_argument(
        "--job", metavar="FILE", default="", help="job file offered when o is pressed"
    )
    defaults = JogSettings()
    parser.add_argument(
        "--first-repeat-timeout",
        type=float,
        metavar="S",
        default=defaults.first_repeat_timeout,
        help="continuous jog: stop if the first key repeat does not come within S seconds "
        f"(covers the terminal's initial repeat delay; default {defaults.first_repeat_timeout:g})",
    )
    parser.add_argument(
        "--repeat-timeout",
        type=float,
        metavar="S",
        default=defaults.repeat_timeout,
        help="continuous jog: stop if the next key repeat does not come within S seconds "
        f"(default {defaults.repeat_timeout:g})",
    )
    parser.set_defaults(handler=run)


def settings_from(args: argparse.Namespace) -> JogSettings:
    try:
        return JogSettings(
            first_repeat_timeout=args.first_repeat_timeout, repeat_timeout=args.repeat_timeout
        )
    except ValidationError as exc:
        raise CliError("; ".join(describe_validation_error(exc))) from None


def run(args: argparse.Namespace) -> int:
    from ..tui import QuadstepApp, Session  # Textual loads only for this command
    from ..tui.port_picker import port_choices, the_one_board

    where = None  # the port picker asks
    if args.port == "auto":
        args.port = None  # the one board, or the picker
    if (
        args.port is None
        and not args.emulator
        and args.sim is None
        and not (args.free or args.trace)
    ):
        one = the_one_board(port_choices())
        if one is not None:
            args.port = one.device  # exactly one board plugged in: that one
    if args.port is not None or args.emulator or args.sim is not None or args.free or args.trace:
        where = target(args)
    path = (
        args.config
        if args.config is not None
        else (DEFAULT_CONFIG if DEFAULT_CONFIG.exists() else None)
    )
    try:
        config = load_config(path) if path is not None else None
    except ConfigError as exc:
        raise CliError(str(exc)) from None
    if config is not None:  # its macros checked now: a bad line named before anything opens
        from ..macro_check import macro_problems
        from ..tui.keys import macro_key_problems

        problems = macro_problems(config, str(path)) + macro_key_problems(config.macros, str(path))
        if problems:
            raise CliError("\n".join(problems))
    session = Session(
        where,
        config,
        settings_from(args),
        config_source=str(path),
        state_file=state_path(path),
        config_path=path,
    )
    app = QuadstepApp(session, job_path=args.job, choose=lambda device: _target(device, args.baud))
    with stops_as_ctrl_c(app):
        app.run()
    print("\n".join(parting_lines(session.parting)))
    return 130 if app.interrupted else 0


@contextmanager
def stops_as_ctrl_c(app: QuadstepApp) -> Iterator[None]:
    """SIGTERM and SIGHUP quit the TUI as Ctrl-C does (motion brought to rest first, exit 130). The
    handler runs in the main thread, inside the app's event loop: a thread of its own hands the
    request to the app."""

    def handler(number: int, frame: FrameType | None) -> None:
        if number == signal.SIGHUP and terminal_hung_up():
            quiet_terminal()
        threading.Thread(
            target=lambda: app.call_from_thread(app.action_interrupt), daemon=True
        ).start()

    with stop_signals_handled(handler):
        yield


STDOUT, STDERR = 1, 2


def terminal_hung_up() -> bool:
    """The terminal is gone (its window closed), not just signalled: it polls as hung up."""
    poller = select.poll()
    poller.register(STDERR, select.POLLOUT)  # where the screen is drawn
    return any(events & (select.POLLHUP | select.POLLERR) for _, events in poller.poll(0))


def quiet_terminal() -> None:
    """Every later write to the closed terminal goes nowhere instead of failing: the screen's
    writer would otherwise die on the first and the app's shutdown wait for it forever."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    for fd in (STDOUT, STDERR):
        os.dup2(devnull, fd)
    os.close(devnull)


def _target(device: str, baud: int) -> Target:
    """What the port picker's choice means: a serial port at the given baud rate, or the
    emulator."""
    from ..tui.port_picker import EMULATOR

    return Target(emulator=True) if device == EMULATOR else Target(port=device, baud=baud)


def parting_lines(parting: Parting | None) -> list[str]:
    """After the TUI: the line a job was stopped at (HOLD) and where the machine rests, as `quadstep
    run` says."""
    if parting is None:
        return []
    end = parting.end
    lines = []
    if parting.line is not None and end is not None:
        lines.append(f"stopped at {parting.label} {parting.line}{' (HOLD)' if end.held else ''}")
    if end is not None and end.error:
        lines.append(f"could not bring the machine to rest: {end.error}")
    return lines + position_lines(parting.machine)
