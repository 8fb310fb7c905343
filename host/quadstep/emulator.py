"""Start the loopback emulator (build/native/quadstep-emu) and connect to it like to a board.

The emulator runs the real firmware core on the host and serves it on a
pseudo-terminal; see firmware/native/README.md for its options and summary.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from .link import DEFAULT_BAUD, Link

REPO = Path(__file__).resolve().parents[2]
EMULATOR_ENV = "QUADSTEP_EMULATOR"
START_TIMEOUT = 10.0
STOP_TIMEOUT = 5.0


class EmulatorError(RuntimeError):
    """The emulator could not be found, built or started."""


def emulator_binary(build: bool = True) -> Path:
    """$QUADSTEP_EMULATOR, else <repo>/build/native/quadstep-emu (built with `make emulator` if missing)."""
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
        result = subprocess.run(["make", "-C", str(REPO), "emulator"], capture_output=True, text=True)
        if result.returncode != 0 or not path.is_file():
            raise EmulatorError(f"`make -C {REPO} emulator` failed:\n{result.stdout[-2000:]}{result.stderr[-2000:]}")
        return path
    raise EmulatorError(
        f"emulator binary not found: set ${EMULATOR_ENV} or build it with `make emulator` in the source tree"
    )


def parse_summary(text: str) -> dict[str, int | str]:
    """The emulator's exit summary: `key=value` lines, integers where they parse."""
    summary: dict[str, int | str] = {}
    for line in text.splitlines():
        key, sep, value = line.strip().partition("=")
        if not sep or not key or " " in key:
            continue
        try:
            summary[key] = int(value)
        except ValueError:
            summary[key] = value
    return summary


class Emulator:
    """A running quadstep-emu; use as a context manager. `.url` is its serial port."""

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
        self.args = [str(self.binary), "--pty", "--tick-hz", str(tick_hz), "--axes", str(axes), "--queue", str(queue)]
        if free:
            self.args.append("--free")
        if trace is not None:
            self.args += ["--trace", str(trace)]
        self.args += list(extra_args)
        self.trace = trace
        self.url = ""
        self.summary: dict[str, int | str] | None = None
        self.returncode: int | None = None
        self._proc: subprocess.Popen[bytes] | None = None
        self._stderr = tempfile.TemporaryFile()

    def start(self) -> Emulator:
        self._proc = subprocess.Popen(self.args, stdout=subprocess.PIPE, stderr=self._stderr, stdin=subprocess.DEVNULL)
        assert self._proc.stdout is not None
        line = self._read_line(self._proc.stdout.fileno())
        if not line.startswith("PORT "):
            self.stop()
            raise EmulatorError(
                f"{' '.join(self.args)} printed {line!r} instead of `PORT <url>`; stderr:\n{self.stderr_text()}"
            )
        self.url = line[5:].strip()
        return self

    def _read_line(self, fd: int) -> str:
        data = b""
        deadline = time.monotonic() + START_TIMEOUT
        while not data.endswith(b"\n"):
            remaining = deadline - time.monotonic()
            if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
                break
            chunk = os.read(fd, 256)
            if not chunk:
                break
            data += chunk
        return data.decode(errors="replace")

    def stderr_text(self) -> str:
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")

    @property
    def pid(self) -> int | None:
        return self._proc.pid if self._proc is not None else None

    @property
    def running(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def stop(self) -> dict[str, int | str]:
        """SIGTERM, wait, and return the exit summary (also kept in .summary)."""
        if self._proc is None:
            return self.summary or {}
        if self._proc.poll() is None:
            self._proc.send_signal(signal.SIGTERM)
            try:
                self._proc.wait(STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        self.returncode = self._proc.returncode
        if self._proc.stdout is not None:
            self._proc.stdout.close()
        self._proc = None
        self.summary = parse_summary(self.stderr_text())
        self._stderr.close()
        return self.summary

    def __enter__(self) -> Emulator:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


@contextmanager
def open_connection(
    port: str | None,
    emulator: bool,
    *,
    baudrate: int = DEFAULT_BAUD,
    **emulator_options: object,
) -> Iterator[Link]:
    """A connected Link to `port`, or to a fresh emulator when `emulator` is true (exactly one of the two)."""
    if emulator == (port is not None):
        raise ValueError("give either a serial port or the emulator, not both or neither")
    if port is not None:
        with Link.open(port, baudrate) as link:
            yield link
        return
    with Emulator(**emulator_options) as emu:  # type: ignore[arg-type]
        with Link.open(emu.url, baudrate) as link:
            link.emulator = emu
            yield link
