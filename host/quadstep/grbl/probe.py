"""G38.2–G38.5 from a sender, as GRBL runs them: the line waits for the machine at rest, the machine
probes (machine/probing.py, what `quadstep probe` runs), and the answer is the latched position as
`[PRB:x,y,z:1]` (machine coordinates), or `:0` with where it stopped for a G38.3/G38.5 that met
nothing, then `ok`. A G38.2/G38.4 that meets nothing raises ALARM:5, a probe already in the state
it looks for ALARM:4 (GRBL's numbers); the line is still answered `ok`, as GRBL does. A feed hold
rests the probe until cycle start goes on with it toward the same target; a reset ends it."""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

from ..link.errors import Stopped
from ..machine import Machine, MachineError
from ..machine.probing import ProbeError, probe
from ..planner.program import Item, ProbeMove
from ..protocol import HoldDone
from .errors import GrblAlarm
from .protocol import numbers

HOLD_TIMEOUT_S = 30.0  # a stop's deceleration to rest, at most


@dataclass(frozen=True)
class ProbeReport:
    """The last probe's position (machine mm) and whether it found its edge: `$#`'s PRB line."""

    machine_mm: tuple[float, ...]
    found: bool

    def line(self) -> str:
        return f"[PRB:{numbers(self.machine_mm)}:{int(self.found)}]"


@dataclass(frozen=True)
class ProbeOutcome:
    report: ProbeReport  # the new one, or the last one kept (a failed G38.2/G38.4)
    alarm: GrblAlarm | None = None
    message: str | None = None


def no_probe(axes: int) -> ProbeReport:
    return ProbeReport((0.0,) * axes, False)


def split_probe(items: Sequence[Item]) -> tuple[list[Item], ProbeMove | None]:
    """What a line asks for before its probe, and the probe. The straight move the interpreter adds
    after a probe (to check what follows as if it went all the way) is dropped: here the lines that
    follow are read after the probe, from where it stopped."""
    for index, item in enumerate(items):
        if isinstance(item, ProbeMove):
            return list(items[:index]), item
    return list(items), None


class ProbeHold:
    """Whether a probe under way is held (feed hold), and what ends the hold: cycle start (the
    probe goes on) or a reset (it ends). Set from the thread that receives the sender's bytes."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._released = threading.Event()
        self._holding = self._at_rest = self._ended = False

    @property
    def state(self) -> str | None:
        """GRBL's Hold:1 while the probe comes to rest, Hold:0 at rest; None when not held."""
        with self._lock:
            if not self._holding:
                return None
            return "Hold:0" if self._at_rest else "Hold:1"

    def start(self) -> None:
        with self._lock:
            self._holding = self._at_rest = self._ended = False

    def hold(self) -> None:
        """Before the HOLD that stops the probe."""
        with self._lock:
            self._holding = True
            self._released.clear()

    def resume(self) -> None:
        self._released.set()

    def end(self) -> None:
        """A reset, or the sender gone: before the HOLD, if the probe is moving."""
        with self._lock:
            self._ended = True
        self._released.set()

    def wait(self) -> bool:
        """At rest after the hold (its position taken): True once cycle start goes on with the
        probe."""
        with self._lock:
            self._at_rest = True
        self._released.wait()
        with self._lock:
            self._holding = self._at_rest = False
            return not self._ended


def run_probe(
    machine: Machine, move: ProbeMove, last: ProbeReport, hold: ProbeHold
) -> ProbeOutcome:
    """Probe on `machine` at rest; a probe that fails keeps `last` as the PRB position. A feed hold
    during it rests it until `hold` says go on (toward the same target, from where it rests); a
    reset's HOLD: MachineError, the machine's position taken where that HOLD leaves it."""
    while True:
        holds = machine.report_count(HoldDone)
        try:
            result = probe(machine, move.code, move.target, move.feed)
        except Stopped:
            stopped = machine.wait_report(HoldDone, holds, timeout=HOLD_TIMEOUT_S)
            machine.standing.rested(stopped.hold_tick if isinstance(stopped, HoldDone) else None)
            if hold.wait():
                continue
            raise MachineError(
                f"G{move.code}: stopped before it finished; the machine rests where it stopped"
            ) from None
        except ProbeError as exc:
            text = str(exc)
            alarm = (
                GrblAlarm.PROBE_FAIL_INITIAL if "already" in text else GrblAlarm.PROBE_FAIL_CONTACT
            )
            return ProbeOutcome(ProbeReport(last.machine_mm, False), alarm, text)
        return ProbeOutcome(ProbeReport(result.machine_mm, result.found))
