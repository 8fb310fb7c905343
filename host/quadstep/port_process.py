"""A child process that serves a board on a pseudo-terminal, as the emulator and the simavr harness
do.

Both print `PORT <url>` on stdout once the port is open, run until SIGTERM,
and then print a summary on stderr: the emulator one JSON object on one line,
the simavr harness `key=value` lines. The child never outlives the program
that started it, however that ends (SIGKILL included): on Linux it gets
SIGTERM when its parent goes (PR_SET_PDEATHSIG).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from typing_extensions import Self  # typing.Self from Python 3.11; not evaluated at run time

START_TIMEOUT = 10.0


def parse_summary(text: str) -> dict[str, Any]:
    """The exit summary: a JSON object on a line of its own, or `key=value` lines (integers where
    they parse)."""
    summary: dict[str, Any] = {}
    for line in text.splitlines():
        if line.startswith("{"):
            try:
                summary.update(json.loads(line))
            except json.JSONDecodeError:
                pass
            continue
        key, sep, value = line.strip().partition("=")
        if not sep or not key or " " in key:
            continue
        try:
            summary[key] = int(value)
        except ValueError:
            summary[key] = value
    return summary


def read_line(fd: int, timeout: float) -> str:
    """One line from `fd`, or what arrived of it before `timeout` seconds or end of file."""
    data = b""
    deadline = time.monotonic() + timeout
    while not data.endswith(b"\n"):
        remaining = deadline - time.monotonic()
        if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
            break
        chunk = os.read(fd, 256)
        if not chunk:
            break
        data += chunk
    return data.decode(errors="replace")


PR_SET_PDEATHSIG = 1  # linux/prctl.h


def die_with_parent() -> Callable[[], None] | None:
    """A preexec function that makes the child get SIGTERM once the thread that forked it ends (None
    off Linux). libc is loaded here, in the parent: the child, between fork and exec, only makes two
    calls."""
    if not sys.platform.startswith("linux"):
        return None
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    parent = os.getpid()

    def preexec() -> None:
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        if os.getppid() != parent:  # the parent went before the prctl: no signal will come
            os._exit(1)

    return preexec


class PortProcess:
    """`args` run as a child serving a port; use as a context manager. `.url` is its serial port."""

    error: type[Exception] = RuntimeError  # raised when the child does not print its port
    stop_timeout = 5.0

    def __init__(self, args: Sequence[str]) -> None:
        self.args = list(args)
        self.url = ""
        self.summary: dict[str, Any] | None = None
        self.returncode: int | None = None
        self._proc: subprocess.Popen[bytes] | None = None
        self._stderr = tempfile.TemporaryFile()
        self._stderr_text: str | None = None  # kept once the child has ended
        # the keeper thread (the child's parent for PR_SET_PDEATHSIG) may end
        self._released = threading.Event()

    def start(self) -> Self:
        """Start the child from a thread that lives until stop() (or the program's end): the
        parent-death signal follows the thread that forked, and the thread calling start() may end
        long before."""
        started, released = threading.Event(), threading.Event()
        self._released = released
        failed: list[BaseException] = []

        def keep() -> None:
            try:
                self._spawn()
            except BaseException as exc:  # handed to start()
                failed.append(exc)
            started.set()
            released.wait()

        threading.Thread(target=keep, name="quadstep-port-process", daemon=True).start()
        started.wait()
        if failed:
            self._released.set()
            raise failed[0]
        try:
            return self._await_port()
        except BaseException:
            self.stop()  # interrupted while it started: it must not be left running
            raise

    def _spawn(self) -> None:
        # A session of its own: the terminal's Ctrl-C (SIGINT to the foreground process group)
        # reaches the program that started the child, which then stops the machine through it; never
        # the child itself.
        self._proc = subprocess.Popen(
            self.args,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
            preexec_fn=die_with_parent(),
        )

    def _await_port(self) -> Self:
        assert self._proc is not None and self._proc.stdout is not None
        line = read_line(self._proc.stdout.fileno(), START_TIMEOUT)
        if not line.startswith("PORT "):
            self.stop()
            raise self.error(
                f"{' '.join(self.args)} printed {line!r} instead of `PORT <url>`; "
                f"stderr:\n{self.stderr_text()}"
            )
        self.url = line[5:].strip()
        return self

    def stderr_text(self) -> str:
        if self._stderr_text is not None:
            return self._stderr_text
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")

    @property
    def pid(self) -> int | None:
        return self._proc.pid if self._proc is not None else None

    @property
    def running(self) -> bool:
        return self._proc is not None and self._proc.poll() is None

    def stop(self) -> dict[str, Any]:
        """SIGTERM, wait, and return the exit summary (also kept in .summary); output files are then
        complete."""
        if self._proc is None:
            self._released.set()
            return self.summary or {}
        if self._proc.poll() is None:
            self._proc.send_signal(signal.SIGTERM)
            try:
                self._proc.wait(self.stop_timeout)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        self.returncode = self._proc.returncode
        if self._proc.stdout is not None:
            self._proc.stdout.close()
        self._proc = None
        self._released.set()
        self._stderr_text = self.stderr_text()
        self._stderr.close()
        self.summary = parse_summary(self._stderr_text)
        return self.summary

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
