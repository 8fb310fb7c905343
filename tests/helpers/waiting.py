"""Waiting for a state, not for a length of time: a test polls what it needs until it holds. A paced
board on a busy computer runs behind the wall clock, so a fixed sleep may find it anywhere; the
deadlines are generous and only end a test that would otherwise hang."""

from __future__ import annotations

import time
from collections.abc import Callable


def wait_until(
    condition: Callable[[], object], timeout: float = 60.0, what: str = "the condition",
    poll: float = 0.005,
) -> None:
    """Return once `condition()` is true; fail the test after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out after {timeout:g} s waiting for {what}"
        time.sleep(poll)
