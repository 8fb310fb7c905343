"""What goes to the sender, in order, never waiting on it.

Answers, reports and alarms come from several threads: the line worker, the thread that receives
the sender's bytes (status reports), the link's reader (a firmware alarm). Each writes at once what
the port takes without waiting (the usual case: no thread hop on the way); what it does not take,
and all that comes while any waits, a thread of the outbox's own writes as the sender reads. So a
sender busy elsewhere only lets its answers wait here, whole and in order."""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

JOIN_S = 5.0


@dataclass(frozen=True)
class SenderPort:
    """How bytes reach the sender: `try_write` writes what the port takes now and says how much
    (BlockingIOError: none), `write` all of it, waiting while the sender reads nothing."""

    try_write: Callable[[bytes], int]
    write: Callable[[bytes], None]


class Outbox:
    """Bytes for the sender through `port`, from any thread."""

    def __init__(self, port: SenderPort) -> None:
        self._try_write, self._write = port.try_write, port.write
        self._lock = threading.Lock()
        self._waiting = threading.Condition(self._lock)
        self._backlog: deque[bytes] = deque()  # for the writer thread, in order
        self._writing = False  # the writer thread has bytes out of the backlog in hand
        self._closing = self._gone = False
        self._thread = threading.Thread(target=self._run, name="grbl-out", daemon=True)
        self._thread.start()

    def put(self, data: bytes) -> None:
        with self._lock:
            if self._gone or self._closing:
                return
            if not self._backlog and not self._writing:
                try:
                    data = data[self._try_write(data) :]
                except BlockingIOError:
                    pass
                except OSError:
                    self._gone = True  # the sender has gone: nobody reads what is left
                    return
                if not data:
                    return
            self._backlog.append(data)
            self._waiting.notify()

    def close(self) -> None:
        """What was put before is written (or the sender has gone), then the writer ends."""
        with self._lock:
            self._closing = True
            self._waiting.notify()
        self._thread.join(timeout=JOIN_S)

    def _run(self) -> None:
        while True:
            with self._lock:
                self._waiting.wait_for(lambda: bool(self._backlog) or self._closing)
                if not self._backlog or self._gone:
                    return
                data = b"".join(self._backlog)
                self._backlog.clear()
                self._writing = True
            try:
                self._write(data)
            except OSError:
                with self._lock:
                    self._gone = True
                return
            finally:
                with self._lock:
                    self._writing = False
