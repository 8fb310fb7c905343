"""`quadstep grbl`'s front door on a machine, for the tests: served on a pseudo-terminal from a
thread while the block runs, then stopped and closed; and what the real senders' tests stream and
probe."""

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


# A CAM-like job: a work offset, the spindle, a plunge, straight cuts and arcs both ways, a retract;
# it ends at X12.5 Y7.25 Z5 in G54.
CAM_JOB = """\
(pocket corner, G54 at X50 Y40 Z-5)
G21 G90 G94
G10 L2 P1 X50 Y40 Z-5
G54
M3 S8000
G0 X0 Y0 Z5
G1 Z-1 F600
G1 X20 F1500
G3 X30 Y10 I0 J10
G1 Y20
G2 X20 Y30 I-10 J0
G1 X0
Y0
G2 X5 Y5 R5
G0 Z5
M5
X12.5 Y7.25
M30
"""


def probe_sim(targets: str) -> str:
    """A simulated machine of three axes at zero whose probe touches `targets` ([[probe.target]]
    tables, in motor steps: docs/SIMULATED_MACHINE.md)."""
    axes = "[[axis]]\nstart = 0\n" * 3
    return f"seed = 1\n{axes}[probe]\nhysteresis = 1\n{targets}"
