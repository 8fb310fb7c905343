"""Stop requests from outside the program: SIGTERM (kill, a service manager) and SIGHUP (the
terminal closed) are handled as Ctrl-C, a controlled stop: whatever moves is brought to rest with
HOLD, the position is printed, and the command exits with 130."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..machine import Machine  # loaded with the commands; the command line starts without it

INTERRUPTED = 130  # the shell's code for a command ended by SIGINT; used for SIGTERM and SIGHUP too
STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)
Handler = Callable[[int, FrameType | None], None]


def _as_interrupt(number: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt(signal.Signals(number).name)


@contextmanager
def stop_signals_handled(handler: Handler) -> Iterator[None]:
    """SIGTERM and SIGHUP go to `handler` while this lasts (a SIGHUP ignored, as under nohup, stays
    ignored); the handlers before it come back after."""
    previous = {sig: signal.getsignal(sig) for sig in STOP_SIGNALS}
    for sig, old in previous.items():
        if old is not signal.SIG_IGN:
            signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


@contextmanager
def stop_signals_as_interrupt() -> Iterator[None]:
    """SIGTERM and SIGHUP raise KeyboardInterrupt in the main thread while this lasts."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    with stop_signals_handled(_as_interrupt):
        yield


def why(exc: KeyboardInterrupt) -> str:
    """ " (SIGTERM)" for a stop signal, "" for Ctrl-C."""
    return f" ({exc.args[0]})" if exc.args else ""


def interrupted(args: argparse.Namespace, machine: Machine, exc: KeyboardInterrupt) -> int:
    """A procedure (homing, probing, a measurement) was interrupted: HOLD, then say where the
    machine rests."""
    from ..machine.probing import hold_to_rest
    from .run import position_lines  # the same lines as a stopped job's

    hold_to_rest(machine)
    print(
        f"quadstep {args.command}: interrupted{why(exc)}: stopped (HOLD)",
        file=sys.stderr,
        flush=True,
    )
    print("\n".join(position_lines(machine)), flush=True)
    return INTERRUPTED
