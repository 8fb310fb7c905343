"""Each line a sender sends, read as it arrives with the modal state of the lines before it, checked
whole (words, feed, arcs, the travel) before it is answered `ok`; a line in error leaves no trace,
not even its modal words. What a line asks for (moves, dwells, outputs, pauses) is handed on to be
run (executor.py).

GRBL starts in G0, so a line with axis words and no motion word moves at rapid. M6 is answered and
ignored, as GRBL does (the sender handles tool changes), unless it is asked to pause; a probing line
(G38.x) is read here and probed by the session (probe.py)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from ..config import MachineConfig
from ..coordinates import SYSTEMS, WorkCoordinates
from ..gcode.interpreter import MM_PER_INCH, GcodeInterpreter
from ..planner.program import Item, JobError, LinearMove
from .protocol import numbers

TOOL_CHANGE = re.compile(r"M\s*0*6(?![\d.])", re.IGNORECASE)
JOG_WORDS = re.compile(
    r"^(?:\s*(?:G\s*(?:20|21|90|91|53)(?![\d.])|[A-Z]\s*[-+.\d]+)\s*)*$", re.IGNORECASE
)
_MODAL = (
    "position",
    "units",
    "absolute",
    "plane",
    "motion",
    "feed",
    "inverse_time",
    "deviation",
    "outputs",
    "tool",
)


class JogError(JobError):
    """A `$J=` line GRBL would refuse as a jog (error 16)."""


@dataclass(frozen=True)
class Read:
    """What one line asks for, and the work coordinates after it."""

    items: list[Item]
    coordinates: WorkCoordinates
    line: int
    ends_program: bool = False  # M2/M30


def check_travel(config: MachineConfig, items: Sequence[Item], line: int) -> None:
    for item in items:
        if not isinstance(item, LinearMove):
            continue
        for axis, x in zip(config.axes, item.target):
            if not axis.travel_min - 1e-9 <= x <= axis.travel_max + 1e-9:
                raise JobError(
                    f"line {line}: {axis.name} {x:.3f} (machine) is outside the travel "
                    f"{axis.travel_min:.3f} … {axis.travel_max:.3f} mm"
                )


class Reader:
    """The sender's lines, numbered from 1 since the last reset, with their modal state."""

    def __init__(
        self,
        config: MachineConfig,
        position_mm: Sequence[float],
        coordinates: WorkCoordinates,
        tool_change: str = "ignore",
    ) -> None:
        self.config = config
        self.tool_change = tool_change  # M6: "ignore" (GRBL's default) or "pause" (as M0)
        self.line = 0
        self.interpreter = self._fresh(position_mm, coordinates)

    def _fresh(
        self, position_mm: Sequence[float], coordinates: WorkCoordinates
    ) -> GcodeInterpreter:
        config = self.config
        return GcodeInterpreter(
            config.axis_names, position_mm, config.arc_tolerance, coordinates=coordinates
        )

    def reset(self, position_mm: Sequence[float], coordinates: WorkCoordinates) -> None:
        """A soft reset: the modal state as at power-up, the offsets kept."""
        self.interpreter = self._fresh(position_mm, coordinates)

    def reset_coordinates(self, coordinates: WorkCoordinates) -> None:
        """The work coordinates set anew ($RST=#); the modal state kept."""
        copy = coordinates.model_copy(deep=True)
        self.interpreter.coords = self.interpreter.program.coordinates = copy

    def reconfigure(self, config: MachineConfig, position_mm: Sequence[float]) -> None:
        """A setting written: the lines that follow are read with `config`, from where the machine
        stands in it (steps/mm may have changed)."""
        self.config = config
        self.interpreter.arc_tolerance = config.arc_tolerance
        self.resync(position_mm)

    def resync(self, position_mm: Sequence[float]) -> None:
        """Where the machine rests now (after a stop or a jog cancelled): lines go on from there."""
        self.interpreter.position = list(position_mm)

    @property
    def coordinates(self) -> WorkCoordinates:
        return self.interpreter.coords

    def read(self, text: str) -> Read:
        """The line's items, checked; raises JobError (and the line leaves nothing) if it is bad."""
        self.line += 1
        if self.tool_change == "ignore":
            text = TOOL_CHANGE.sub("", text)
        return self._read(text, self.interpreter, self.line)

    def jog(self, text: str) -> Read:
        """A `$J=` line: G1 at its F, G20/G21/G90/G91/G53 for this line only; the modal state
        stays."""
        self.line += 1
        if not JOG_WORDS.match(text) or "F" not in text.upper():
            raise JogError(
                f"jog {text!r}: a jog is axis words and F, with G20 G21 G90 G91 G53 only"
            )
        base = self.interpreter
        jog = GcodeInterpreter(
            self.config.axis_names,
            base.position,
            self.config.arc_tolerance,
            coordinates=base.coords,
        )
        jog.units, jog.absolute, jog.motion = base.units, base.absolute, 1
        read = self._read(text, jog, self.line)
        base.position = list(jog.position)
        return Read(read.items, base.coords.model_copy(deep=True), read.line)

    def _read(self, text: str, interpreter: GcodeInterpreter, line: int) -> Read:
        saved = {name: getattr(interpreter, name) for name in _MODAL}
        saved["position"] = list(interpreter.position)
        coordinates = interpreter.coords.model_copy(deep=True)
        program = interpreter.program
        try:
            goes_on = interpreter.feed_line(text, line)
            check_travel(self.config, program.items, line)
        except JobError:
            for name, value in saved.items():
                setattr(interpreter, name, value)
            interpreter.coords = program.coordinates = coordinates
            program.items.clear()
            raise
        finally:
            program.skipped.clear()
        items = list(program.items)
        program.items.clear()
        return Read(items, interpreter.coords.model_copy(deep=True), line, not goes_on)

    # --- what $G and $# show --------------------------------------------------------------

    def modal_report(self) -> str:
        i = self.interpreter
        units = i.units
        coolant = [m for m, on in (("M7", i.outputs.mist), ("M8", i.outputs.flood)) if on] or ["M9"]
        words = [
            f"G{i.motion if i.motion is not None else 80}",
            i.coords.name,
            f"G{i.plane}",
            "G20" if units == MM_PER_INCH else "G21",
            "G90" if i.absolute else "G91",
            "G93" if i.inverse_time else "G94",
            f"M{i.outputs.spindle}",
            *coolant,
            f"T{i.tool or 0}",
            f"F{(i.feed or 0.0) * 60 / units:g}",
            f"S{i.outputs.speed:g}",
        ]
        return f"[GC:{' '.join(words)}]"

    def offsets_report(self, probe: str) -> list[str]:
        """`$#`, with `probe` the PRB line (probe.py)."""
        names = self.config.axis_names
        c = self.interpreter.coords
        lines = [
            f"[{system}:{numbers([c.offsets[k].get(a, 0.0) for a in names])}]"
            for k, system in enumerate(SYSTEMS)
        ]
        lines.append(f"[G28:{numbers([c.stored(28, a) for a in names])}]")
        lines.append(f"[G30:{numbers([c.stored(30, a) for a in names])}]")
        lines.append(
            f"[G92:{numbers([c.g92.get(a, 0.0) if c.g92_applied else 0.0 for a in names])}]"
        )
        lines.append(f"[TLO:{c.tlo:.3f}]")
        lines.append(probe)
        return lines
