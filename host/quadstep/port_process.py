"""A child process that serves a board on a pseudo-terminal, as the emulator and the simavr harness do.

Both print `PORT <url>` on stdout once the port is open, run until SIGTERM,
and then print a summary on stderr: the emulator one JSON object on one line,
the simavr harness `key=value` lines.
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import tempfile
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from typing import Self  # Python 3.11; annotations are not evaluated at run time

START_TIMEOUT = 10.0


def parse_summary(text: str) -> dict[str, Any]:
    """The exit summary: a JSON object on a line of its own, or `key=value` lines (integers where they parse)."""
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

    def start(self) -> Self:
        # A session of its own: the terminal's Ctrl-C (SIGINT to the foreground process group) reaches the
        # program that started the child, which then stops the machine through it; never the child itself.
        self._proc = subprocess.Popen(self.args, stdout=subprocess.PIPE, stderr=self._stderr, stdin=subprocess.DEVNULL,
                                      start_new_session=True)
        assert self._proc.stdout is not None
        line = read_line(self._proc.stdout.fileno(), START_TIMEOUT)
        if not line.startswith("PORT "):
            self.stop()
            raise self.error(
                f"{' '.join(self.args)} printed {line!r} instead of `PORT <url>`; stderr:\n{self.stderr_text()}"
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
        """SIGTERM, wait, and return the exit summary (also kept in .summary); output files are then complete."""
        if self._proc is None:
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
        self._stderr_text = self.stderr_text()
        self._stderr.close()
        self.summary = parse_summary(self._stderr_text)
        return self.summary

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
