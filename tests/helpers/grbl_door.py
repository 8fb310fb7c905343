"""`quadstep grbl`'s front door on a machine, for the tests: served on a pseudo-terminal from a thread
while the block runs, then stopped and closed."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from quadstep.cli.grbl import serve_in_thread
from quadstep.grbl.server import PtyServer
from quadstep.grbl.session import SessionOptions
from quadstep.machine import Machine


@contextmanager
def serving(machine: Machine, options: SessionOptions | None = None) -> Iterator[PtyServer]:
    pty = PtyServer(machine) if options is None else PtyServer(machine, options=options)
    thread = serve_in_thread(pty)
    try:
        yield pty
    finally:
        pty.stop()
        thread.join(timeout=10)
        pty.close()
