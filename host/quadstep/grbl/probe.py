"""G38.2–G38.5 from a sender, as GRBL runs them: the line waits for the machine at rest, the machine
probes (machine/probing.py, what `quadstep probe` runs), and the answer is the latched position as
`[PRB:x,y,z:1]` (machine coordinates), or `:0` with where it stopped for a G38.3/G38.5 that met
nothing, then `ok`. A G38.2/G38.4 that meets nothing raises ALARM:5, a probe already in the state
it looks for ALARM:4 (GRBL's numbers); the line is still answered `ok`, as GRBL does."""

from __future__ import annotations

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


def run_probe(machine: Machine, move: ProbeMove, last: ProbeReport) -> ProbeOutcome:
    """Probe on `machine` at rest; a probe that fails keeps `last` as the PRB position. A stop
    (feed hold, reset: the session's HOLD) during it: MachineError, the machine's position taken
    where that HOLD leaves it."""
    holds = machine.report_count(HoldDone)
    try:
        result = probe(machine, move.code, move.target, move.feed)
    except Stopped:
        stopped = machine.wait_report(HoldDone, holds, timeout=HOLD_TIMEOUT_S)
        machine.standing.rested(stopped.hold_tick if isinstance(stopped, HoldDone) else None)
        raise MachineError(
            f"G{move.code}: stopped before it finished; the machine rests where it stopped"
        ) from None
    except ProbeError as exc:
        text = str(exc)
        alarm = GrblAlarm.PROBE_FAIL_INITIAL if "already" in text else GrblAlarm.PROBE_FAIL_CONTACT
        return ProbeOutcome(ProbeReport(last.machine_mm, False), alarm, text)
    return ProbeOutcome(ProbeReport(result.machine_mm, result.found))
