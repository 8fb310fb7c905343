"""Shared by the jog and TUI tests: the test machine and key timing."""

from __future__ import annotations

from typing import Any

from quadstep.jog import JogSettings

# Short travel and brisk limits keep continuous jogs to the soft limit well under a second.
MACHINE: dict[str, Any] = {
    "tick_hz": 50000,
    "axes": [
        {"name": "X", "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 40},
        {"name": "Y", "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 40},
        {"name": "Z", "steps_per_mm": 400, "max_speed": 10, "max_accel": 200, "travel_min": -20, "travel_max": 0},
    ],
}

# Repeats every 40 ms after a 0.3 s initial delay (a fast terminal); the timeouts cover both with
# room for a busy test machine, where a late repeat would end the jog and the next start another.
FAST_RELEASE = JogSettings(first_repeat_timeout=0.6, repeat_timeout=0.3, lookahead=1.0)
# Jogs that no inferred release ends (only a stop key or the soft limit). Tests not about the
# lookahead queue a second ahead, so that a test machine too busy to feed the board in time
# cannot end them in UNDERRUN (a stop never waits on the queue: HOLD drops the queued tail).
HELD_UNTIL_STOPPED = JogSettings(first_repeat_timeout=5.0, repeat_timeout=5.0, lookahead=1.0)


async def until(pilot, predicate, timeout: float = 30.0, what: str = "condition") -> None:  # noqa: ANN001
    """Let the app run until predicate() holds; fail naming `what` after `timeout` seconds (generous: a loaded
    test machine can take seconds to start an emulator or a job; no figure is measured here)."""
    import time

    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}; the log:\n{log_text(pilot.app)}")
        await pilot.pause(0.02)


def log_text(app) -> str:  # noqa: ANN001
    """Everything the message log shows, one message a line."""
    return "\n".join(app.machine.messages)


def read_holds(path) -> list[tuple[int, int]]:  # noqa: ANN001
    """(hold_tick, monotonic_ns) of every hold in an emulator --events file."""
    rows = []
    for line in path.read_text().splitlines()[1:]:
        kind, tick, ns = line.split(",")
        if kind == "hold":
            rows.append((int(tick), int(ns)))
    return rows


async def hold_key(app, key: str, seconds: float, first_delay: float = 0.3, interval: float = 0.04) -> None:  # noqa: ANN001
    """A held key as a terminal sends it: one press, then repeats after an initial delay.

    The events go straight to the app's queue, as the terminal driver puts them,
    without waiting for the screen to settle after each (pilot.press does).
    """
    import asyncio
    import time

    from textual import events

    end = time.monotonic() + seconds
    app.post_message(events.Key(key, None))
    await asyncio.sleep(first_delay)
    while time.monotonic() < end:
        app.post_message(events.Key(key, None))
        await asyncio.sleep(interval)


def send_key(app, key: str, char: str | None = None) -> None:  # noqa: ANN001
    """One key event into the app's queue, as the terminal driver delivers it (no waiting)."""
    from textual import events

    app.post_message(events.Key(key, char))


def read_terminal(fd: int, out: bytearray, until: bytes | None, seconds: float) -> bool:
    """Read a terminal's output into `out` until it shows `until` (or for `seconds`); whether it did."""
    import os
    import select
    import time

    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and (until is None or until not in out):
        if select.select([fd], [], [], 0.05)[0]:
            try:
                out += os.read(fd, 65536)
            except OSError:
                break
    return until is None or until in out


def exit_code(pid: int, seconds: float) -> int | None:
    """The exit code of child `pid` once it ends within `seconds`; None if it had to be killed."""
    import os
    import time

    deadline = time.monotonic() + seconds
    done, status = os.waitpid(pid, os.WNOHANG)
    while not done and time.monotonic() < deadline:
        time.sleep(0.05)
        done, status = os.waitpid(pid, os.WNOHANG)
    if not done:
        os.kill(pid, 9)
        os.waitpid(pid, 0)
        return None
    return os.waitstatus_to_exitcode(status)


async def open_job(pilot) -> None:  # noqa: ANN001
    """o, Enter on the path offered: the job is planned and shown; Enter again runs it (unless it was
    refused: then the log says so, and nothing is shown to run)."""
    app = pilot.app
    await pilot.press("o", "enter")
    await until(pilot, lambda: app.machine.preview is not None or "job not started" in log_text(app),
                what="the job shown")
    if app.machine.preview is not None:
        await pilot.press("enter")
