"""Work coordinates as GRBL and LinuxCNC have them: six work offsets (G54–G59), the G92 offset on
top, and the two stored positions of G28 and G30.

Everything is in mm, keyed by axis name. A machine coordinate is what the
steps say (through the configuration); a work coordinate is the machine
coordinate minus the work offset of the active system, while it is
applied the G92 offset, and on Z the tool length offset (G43.1, as GRBL
has it):

    work = machine − offsets[system] − (g92 if g92_applied else 0) − (tlo on Z)

Soft limits are always machine coordinates. The model is the state file's
form (machine/state.py); the G-code interpreter works on a copy of it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

SYSTEMS = ("G54", "G55", "G56", "G57", "G58", "G59")
TOOL_LENGTH_AXIS = "Z"  # G43.1's axis, as GRBL's

Offsets = dict[str, float]


def _six() -> list[Offsets]:
    return [{} for _ in SYSTEMS]


class WorkCoordinates(BaseModel):
    """Work offsets, G92, and the G28/G30 positions; axes not named are 0."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True)

    system: int = Field(default=1, ge=1, le=len(SYSTEMS), description="1 = G54 … 6 = G59")
    offsets: list[Offsets] = Field(
        default_factory=_six, min_length=len(SYSTEMS), max_length=len(SYSTEMS)
    )
    g92: Offsets = Field(default_factory=dict)
    # G92 sets and applies; G92.2 suspends (values kept), G92.3 applies them again
    g92_applied: bool = False
    g28: Offsets = Field(default_factory=dict, description="machine mm")
    g30: Offsets = Field(default_factory=dict, description="machine mm")
    tlo: float = Field(default=0.0, description="G43.1's tool length offset on Z, mm; G49: 0")

    def __deepcopy__(self, memo: dict[int, Any] | None = None) -> WorkCoordinates:
        """The copy model_copy(deep=True) makes, without deepcopy's walk: every value is a number,
        and a G-code sender's every line takes two."""
        return type(self).model_construct(
            set(self.model_fields_set),
            system=self.system,
            offsets=[dict(offsets) for offsets in self.offsets],
            g92=dict(self.g92),
            g92_applied=self.g92_applied,
            g28=dict(self.g28),
            g30=dict(self.g30),
            tlo=self.tlo,
        )

    @property
    def name(self) -> str:
        """The active system: G54 … G59."""
        return SYSTEMS[self.system - 1]

    def offset(self, axis: str) -> float:
        """The active system's offset of `axis` with G92 and the tool length on top: machine −
        work."""
        return self.offset_in(self.system, axis)

    def offset_in(self, system: int, axis: str) -> float:
        """System `system`'s (1 = G54) offset of `axis` with G92 and the tool length on top."""
        return self.offsets[system - 1].get(axis, 0.0) + self._on_top(axis)

    def _on_top(self, axis: str) -> float:
        """What is added to every system's offset of `axis`: G92 where applied, the tool length
        on Z."""
        g92 = self.g92.get(axis, 0.0) if self.g92_applied else 0.0
        return g92 + (self.tlo if axis == TOOL_LENGTH_AXIS else 0.0)

    def to_work(self, axes: Sequence[str], machine: Sequence[float]) -> tuple[float, ...]:
        return tuple(x - self.offset(a) for a, x in zip(axes, machine))

    def to_machine(self, axes: Sequence[str], work: Sequence[float]) -> tuple[float, ...]:
        return tuple(x + self.offset(a) for a, x in zip(axes, work))

    # --- changes (each keeps the other axes as they are) ------------------------------------------

    def set_offset(self, system: int, axis: str, mm: float) -> None:
        """G10 L2 Pn: the offset of system n (0: the active one) is `mm` (machine mm of its
        origin)."""
        index = (system or self.system) - 1
        offsets = [dict(o) for o in self.offsets]
        offsets[index][axis] = mm
        self.offsets = offsets

    def set_position(self, system: int, axis: str, machine: float, work: float) -> None:
        """G10 L20 Pn (and the zero keys): make the machine coordinate `machine` read `work` in
        system n."""
        self.set_offset(system, axis, machine - self._on_top(axis) - work)

    def set_g92(self, axis: str, machine: float, work: float) -> None:
        """G92: make the machine coordinate `machine` read `work`, on top of the active system."""
        tlo = self.tlo if axis == TOOL_LENGTH_AXIS else 0.0
        system = self.offsets[self.system - 1].get(axis, 0.0)
        self.g92 = {**self.g92, axis: machine - system - tlo - work}
        self.g92_applied = True

    def clear_g92(self) -> None:
        """G92.1: G92 offsets to zero, and forgotten."""
        self.g92 = {}
        self.g92_applied = False

    def suspend_g92(self) -> None:
        """G92.2: G92 offsets no longer applied; G92.3 applies them again."""
        self.g92_applied = False

    def restore_g92(self) -> None:
        """G92.3: the G92 offsets kept are applied again."""
        self.g92_applied = bool(self.g92)

    def store(self, which: int, axes: Sequence[str], machine: Sequence[float]) -> None:
        """G28.1 / G30.1: remember the machine position."""
        stored = {a: x for a, x in zip(axes, machine)}
        if which == 28:
            self.g28 = stored
        else:
            self.g30 = stored

    def stored(self, which: int, axis: str) -> float:
        """The G28 or G30 position of `axis`, machine mm (0 until stored)."""
        return (self.g28 if which == 28 else self.g30).get(axis, 0.0)

    def program_end(self) -> None:
        """M2/M30 as RS274/NGC has it: back to G54, G92 offsets no longer applied (kept for
        G92.3)."""
        self.system = 1
        self.g92_applied = False
