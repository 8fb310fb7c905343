"""Key release from key repeats: terminals report presses and repeats, never the release.

A held key repeats after the terminal's initial delay, then at its repeat
rate. The key counts as released once no repeat arrived in time: within
`first_timeout` of the first press (which must cover the initial delay),
within `repeat_timeout` of any later one.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable


class ReleaseDetector:
    """Thread-safe: press() from the UI, deadline()/released() from a watcher thread."""

    def __init__(
        self,
        first_timeout: float,
        repeat_timeout: float,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.first_timeout = first_timeout
        self.repeat_timeout = repeat_timeout
        self._clock = clock
        self._lock = threading.Lock()
        self._presses = 0
        self._deadline = 0.0

    def press(self) -> None:
        """A press or a repeat of the held key."""
        now = self._clock()
        with self._lock:
            self._presses += 1
            timeout = self.first_timeout if self._presses == 1 else self.repeat_timeout
            self._deadline = max(self._deadline, now + timeout)

    @property
    def presses(self) -> int:
        with self._lock:
            return self._presses

    def deadline(self) -> float:
        """The clock time after which, without another press, the key is released."""
        with self._lock:
            return self._deadline

    def released(self, now: float | None = None) -> bool:
        return (self._clock() if now is None else now) >= self.deadline()
