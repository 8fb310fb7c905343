"""Start the loopback emulator (build/native/quadstep-emu) and connect to it like to a board.

The emulator runs the real firmware core on the host and serves it on a
pseudo-terminal; see firmware/native/README.md for its options and summary.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .link import DEFAULT_BAUD, Link
from .port_process import PortProcess, parse_summary  # noqa: F401  (parse_summary: part of this module's API)

REPO = Path(__file__).resolve().parents[2]
EMULATOR_ENV = "QUADSTEP_EMULATOR"


class EmulatorError(RuntimeError):
    """The emulator could not be found, built or started."""


def emulator_binary(build: bool = True) -> Path:
    """$QUADSTEP_EMULATOR, else <repo>/build/native/quadstep-emu (built with `make emulator` if
    missing)."""
    env = os.environ.get(EMULATOR_ENV)
    if env:
        path = Path(env)
        if not path.is_file():
            raise EmulatorError(f"${EMULATOR_ENV} names {path}, which does not exist")
        return path
    path = REPO / "build" / "native" / "quadstep-emu"
    if path.is_file():
        return path
    if build and (REPO / "Makefile").is_file():
        result = subprocess.run(
            ["make", "-C", str(REPO), "emulator"], capture_output=True, text=True
        )
        if result.returncode != 0 or not path.is_file():
            raise EmulatorError(
                f"`make -C {REPO} emulator` failed:\n{result.stdout[-2000:]}{result.stderr[-2000:]}"
            )
        return path
    raise EmulatorError(
        f"emulator binary not found: set ${EMULATOR_ENV} or build it with `make emulator` in the "
        "source tree"
    )


class Emulator(PortProcess):
    """A running quadstep-emu; use as a context manager. `.url` is its serial port."""

    error = EmulatorError

    def __init__(
        self,
        free: bool = False,
        tick_hz: int = 50_000,
        axes: int = 4,
        queue: int = 32,
        trace: Path | None = None,
        extra_args: Sequence[str] = (),
        binary: Path | None = None,
    ) -> None:
        self.binary = binary or emulator_binary()
        args = [
            str(self.binary),
            "--pty",
            "--tick-hz",
            str(tick_hz),
            "--axes",
            str(axes),
            "--queue",
            str(queue),
        ]
        if free:
            args.append("--free")
        if trace is not None:
            args += ["--trace", str(trace)]
        super().__init__([*args, *extra_args])
        self.trace = trace


@contextmanager
def open_connection(
    port: str | None,
    emulator: bool,
    *,
    baudrate: int = DEFAULT_BAUD,
    **emulator_options: Any,  # Emulator's options
) -> Iterator[Link]:
    """A connected Link to `port`, or to a fresh emulator when `emulator` is true (exactly one of
    the two)."""
    if emulator == (port is not None):
        raise ValueError("give either a serial port or the emulator, not both or neither")
    if port is not None:
        with Link.open(port, baudrate) as link:
            yield link
        return
    with Emulator(**emulator_options) as emu:
        with Link.open(emu.url, baudrate) as link:
            yield link
