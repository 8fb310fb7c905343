"""A G-code sender written from GRBL 1.1's interface documentation, for testing `quadstep grbl`: it reads
every line GRBL sends in a thread of its own, sorts them (answers `ok`/`error:N`, status reports `<…>`,
the rest: banner, [MSG:…], ALARM:N, $ output) and streams a file in either of GRBL's two ways:

- send-response: a line, then wait for its answer;
- character counting: keep the bytes sent and not yet answered within GRBL's 128-byte receive buffer,
  counting each line with its newline, and send the next line as soon as it fits."""

from __future__ import annotations

import queue
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import Self

import serial

RX_BUFFER = 128
TIMEOUT = 20.0


class SocketPort:
    """TCP (socket://HOST:PORT) read and written like a serial port; what came before a close is kept."""

    def __init__(self, url: str) -> None:
        host, _, port = url.removeprefix("socket://").rpartition(":")
        self._socket = socket.create_connection((host, int(port)), timeout=5)
        self._socket.settimeout(0.05)

    def read(self, size: int) -> bytes:
        try:
            data = self._socket.recv(size)
        except TimeoutError:
            return b""
        if not data:
            raise OSError("closed by the other end")
        return data

    def write(self, data: bytes) -> None:
        self._socket.sendall(data)

    def close(self) -> None:
        self._socket.close()


class GrblClient:
    def __init__(self, url: str) -> None:
        self.port: serial.Serial | SocketPort = (
            SocketPort(url) if url.startswith("socket://") else serial.Serial(url, timeout=0.05)
        )
        self.answers: queue.Queue[str] = queue.Queue()
        self.reports: queue.Queue[str] = queue.Queue()
        self.other: queue.Queue[str] = queue.Queue()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self.port.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _read(self) -> None:
        pending = b""
        while not self._stop.is_set():
            try:
                # what has come, as soon as a byte has (a serial read of more waits out its timeout)
                waiting = self.port.in_waiting if isinstance(self.port, serial.Serial) else 4096
                pending += self.port.read(max(1, waiting))
            except (serial.SerialException, OSError):
                return
            while b"\n" in pending:
                raw, pending = pending.split(b"\n", 1)
                line = raw.decode("ascii").strip()
                if line in ("ok",) or line.startswith("error:"):
                    self.answers.put(line)
                elif line.startswith("<"):
                    self.reports.put(line)
                elif line:
                    self.other.put(line)

    # --- waiting for what GRBL says ----------------------------------------------------------------

    def expect_other(self, predicate: Callable[[str], bool], timeout: float = TIMEOUT) -> list[str]:
        """The non-answer lines up to and including the first that `predicate` accepts."""
        seen: list[str] = []
        deadline = time.monotonic() + timeout
        while True:
            line = self.other.get(timeout=max(0.0, deadline - time.monotonic()))
            seen.append(line)
            if predicate(line):
                return seen

    def wait_banner(self) -> None:
        self.expect_other(lambda line: line.startswith("Grbl 1.1"))

    def answer(self, timeout: float = TIMEOUT) -> str:
        return self.answers.get(timeout=timeout)

    def drain_other(self) -> list[str]:
        lines = []
        while not self.other.empty():
            lines.append(self.other.get_nowait())
        return lines

    # --- commands -----------------------------------------------------------------------------------

    def realtime(self, byte: int) -> None:
        self.port.write(bytes([byte]))

    def command(self, line: str) -> tuple[list[str], str]:
        """Send-response: the lines it printed (after those before it) and its answer."""
        self.drain_other()
        self.port.write(line.encode("ascii") + b"\n")
        answer = self.answer()
        return self.drain_other(), answer

    def status(self) -> str:
        self.port.write(b"?")
        return self.reports.get(timeout=TIMEOUT)

    def wait_status(self, predicate: Callable[[str], bool], timeout: float = TIMEOUT) -> str:
        """Poll `?` until a report satisfies `predicate`."""
        deadline = time.monotonic() + timeout
        while True:
            report = self.status()
            if predicate(report):
                return report
            assert time.monotonic() < deadline, f"timed out; last report {report}"
            time.sleep(0.02)

    def stream_send_response(self, lines: Sequence[str]) -> list[str]:
        answers = []
        for line in lines:
            self.port.write(line.encode("ascii") + b"\n")
            answers.append(self.answer())
        return answers

    def stream_counting(self, lines: Sequence[str], buffer: int = RX_BUFFER) -> list[str]:
        """Character counting: a line goes when it fits in what the receive buffer has left; each answer
        frees the oldest line's bytes. Returns the answers in order."""
        in_flight: deque[int] = deque()
        answers: list[str] = []
        for line in lines:
            data = line.encode("ascii") + b"\n"
            assert len(data) <= buffer, f"line longer than GRBL's buffer: {line!r}"
            while sum(in_flight) + len(data) > buffer:
                answers.append(self.answer())
                in_flight.popleft()
            self.port.write(data)
            in_flight.append(len(data))
        while in_flight:
            answers.append(self.answer())
            in_flight.popleft()
        return answers


def report_fields(report: str) -> dict[str, str]:
    """`<Idle|MPos:1.000,2.000,3.000|FS:0,0>` → {"state": "Idle", "MPos": "1.000,2.000,3.000", ...}."""
    assert report.startswith("<") and report.endswith(">"), report
    state, *fields = report[1:-1].split("|")
    parsed = {"state": state}
    for field in fields:
        name, _, value = field.partition(":")
        parsed[name] = value
    return parsed


def mpos(report: str) -> tuple[float, ...]:
    return tuple(float(x) for x in report_fields(report)["MPos"].split(","))
