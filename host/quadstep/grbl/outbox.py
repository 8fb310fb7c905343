"""What goes to the sender, written in order by one thread of its own.

Answers, reports and alarms come from several threads: the line worker, the thread that receives
the sender's bytes (status reports), the link's reader (a firmware alarm). None of them waits for
the sender to read: a sender busy elsewhere only lets its answers wait here, whole and in order."""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable

JOIN_S = 5.0


class Outbox:
    """Bytes for `write` (which may wait while the sender reads nothing), from any thread."""

    def __init__(self, write: Callable[[bytes], None]) -> None:
        self._write = write
        self._queue: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="grbl-out", daemon=True)
        self._thread.start()

    def put(self, data: bytes) -> None:
        self._queue.put(data)

    def close(self) -> None:
        """What was put before is written (or the sender has gone), then the writer ends."""
        self._queue.put(None)
        self._thread.join(timeout=JOIN_S)

    def _run(self) -> None:
        while (data := self._queue.get()) is not None:
            waiting, closing = self._waiting()
            try:
                self._write(data + waiting)  # what came meanwhile, in one write
            except OSError:
                return  # the sender has gone: what is left has nobody to read it
            if closing:
                return

    def _waiting(self) -> tuple[bytes, bool]:
        """What was put since, and whether close() came after it."""
        chunks: list[bytes] = []
        while True:
            try:
                data = self._queue.get_nowait()
            except queue.Empty:
                return b"".join(chunks), False
            if data is None:
                return b"".join(chunks), True
            chunks.append(data)
