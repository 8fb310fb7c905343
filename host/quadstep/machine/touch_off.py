"""Touch-off as senders run it, on the machine's probing (probing.py).

Z on a plate: a fast touch, back off, a slow touch; the work Z zero is the slow contact less the
plate's thickness (the surface the plate lies on), and Z ends a safe height above it. An edge: Z
goes down beside the stock, the axis touches the face twice the same way, and the edge (the contact
plus the tool's radius toward the face) becomes that axis's zero. A corner is two edges, each probed
a set offset along its face. A bore's or a boss's centre is the midpoint of the contacts on ±X, then
on ±Y through the new X centre. Every zero is a work offset of the active system (G10 L20), kept;
machine coordinates never change.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..planner.plan import plan_program
from ..planner.program import LinearMove, Program
from ..touch_off_settings import TouchOffSettings
from .errors import MachineError
from .machine import Machine
from .probing import probe

Say = Callable[[str], None]
MOVE_TIMEOUT = 600.0  # s for any one move


class TouchOffError(MachineError):
    """A touch-off that could not go on: no contact, contact where none should be, or stopped."""


@dataclass(frozen=True)
class TouchOffResult:
    """What a touch-off found: the zeros set (machine mm of each axis's new work zero)."""

    what: str
    zero_mm: dict[str, float]
    system: str

    def describe(self) -> str:
        zeros = "  ".join(f"{axis} {mm:.4f}" for axis, mm in self.zero_mm.items())
        return f"{self.what}: work zero in {self.system} at machine {zeros} mm"


class TouchOff:
    """The routines on one machine; stop() (any thread) ends the one running at its next step."""

    def __init__(self, machine: Machine, settings: TouchOffSettings, say: Say | None = None):
        self.machine = machine
        self.config = machine.config
        self.settings = settings
        self.say = say or (lambda text: None)
        self._stopped = threading.Event()

    def stop(self) -> None:
        self._stopped.set()
        self.machine.hold("stop")

    # --- the routines -----------------------------------------------------------------------

    def z(self, plate: float | None = None) -> TouchOffResult:
        """Z down onto a plate of `plate` mm (default: the settings'); zero on the surface below."""
        thickness = self.settings.plate if plate is None else plate
        z = self._axis("Z")
        contact = self._double_touch(z, -1)
        zero = self._set_zero({z: contact - thickness})
        top = self.config.axes[z].travel_max
        self._move_axis(z, min(zero[z] + self.settings.safe, top))
        return self._result(f"Z on a {thickness:g} mm plate", zero)

    def edge(self, axis: str, direction: int, radius: float | None = None) -> TouchOffResult:
        """`axis` toward a face in `direction` (±1), from beside the stock: zero on the face."""
        index = self._axis(axis)
        edge = self._edge(index, direction, self._radius(radius))
        zero = self._set_zero({index: edge})
        return self._result(f"{axis.upper()}{'+' if direction > 0 else '−'} edge", zero)

    def corner(
        self, x_direction: int, y_direction: int, radius: float | None = None
    ) -> TouchOffResult:
        """From outside a corner (diagonally off it): X toward its face `offset` along Y, then Y
        toward its face `offset` along X; both zeros on the corner, the tool back at the start."""
        x, y = self._axis("X"), self._axis("Y")
        r, offset = self._radius(radius), self.settings.offset
        start = self.machine.position_mm
        self._move_axis(y, start[y] + y_direction * offset)
        x_edge = self._edge(x, x_direction, r)
        self._move_axis(y, start[y])
        self._move_axis(x, start[x] + x_direction * offset)
        y_edge = self._edge(y, y_direction, r)
        self._move_axis(y, start[y])
        self._move_axis(x, start[x])
        zero = self._set_zero({x: x_edge, y: y_edge})
        return self._result("corner", zero)

    def bore(self) -> TouchOffResult:
        """From inside a bore at the height to probe: ±X, the X centre, ±Y there: the centre."""
        x, y = self._axis("X"), self._axis("Y")
        centre = {}
        for axis in (x, y):
            start = self.machine.position_mm[axis]
            plus = self._double_touch(axis, 1)
            self._move_axis(axis, start)
            minus = self._double_touch(axis, -1)
            centre[axis] = (plus + minus) / 2
            self._move_axis(axis, centre[axis])
        zero = self._set_zero(centre)
        return self._result("bore centre", zero)

    def boss(self, size: float) -> TouchOffResult:
        """Above a boss about `size` mm across: each side from outside it (Z down `depth` beside
        it), X then Y; the centre."""
        x, y = self._axis("X"), self._axis("Y")
        reach = size / 2 + self.settings.offset
        centre = {}
        for axis in (x, y):
            start = self.machine.position_mm[axis]
            contacts = []
            for direction in (1, -1):
                self._move_axis(axis, start - direction * reach)
                contacts.append(self._edge(axis, direction, 0.0))
                self._move_axis(axis, start)
            centre[axis] = sum(contacts) / 2
            self._move_axis(axis, centre[axis])
        zero = self._set_zero(centre)
        return self._result("boss centre", zero)

    # --- the steps ------------------------------------------------------------------------

    def _edge(self, axis: int, direction: int, radius: float) -> float:
        """Down `depth` (a probing move: contact there means the tool is over the stock), the face
        touched twice, back off, up again: the face's machine mm (the contact plus the radius)."""
        z = self._axis("Z")
        top = self.machine.position_mm[z]
        self._check()
        down = list(self.machine.position_mm)
        down[z] -= self.settings.depth
        if probe(self.machine, "38.3", down, self.settings.fast).found:
            self._move_axis(z, top)
            raise TouchOffError(
                f"the probe touched going down {self.settings.depth:g} mm: start beside the stock"
            )
        contact = self._double_touch(axis, direction)
        self._move_axis(z, top)
        return contact + direction * radius

    def _double_touch(self, axis: int, direction: int) -> float:
        """A fast touch, back off `retract`, a slow touch: the slow contact's machine mm."""
        s = self.settings
        name = self.config.axes[axis].name
        self.say(f"{name}: first touch at {s.fast:g} mm/s")
        first = self._touch(axis, direction, s.distance, s.fast)
        self._move_axis(axis, first - direction * s.retract)
        self.say(f"{name}: second touch at {s.slow:g} mm/s")
        second = self._touch(axis, direction, s.retract * 2, s.slow)
        self._move_axis(axis, second - direction * s.retract)
        return second

    def _touch(self, axis: int, direction: int, distance: float, feed: float) -> float:
        self._check()
        cfg = self.config.axes[axis]
        target = list(self.machine.position_mm)
        target[axis] = min(cfg.travel_max, max(cfg.travel_min, target[axis] + direction * distance))
        result = probe(self.machine, "38.2", target, feed)
        return result.machine_mm[axis]

    def _move_axis(self, axis: int, mm: float) -> None:
        target = list(self.machine.position_mm)
        target[axis] = mm
        self._move(target)

    def _move(self, target: Sequence[float]) -> None:
        """A straight move at the axes' own speed (G0), to rest."""
        self._check()
        start = self.machine.sync()
        program = Program(items=[LinearMove(line=1, target=tuple(target), feed=None)], lines=1)
        plan = plan_program(program, self.config, start, "touch-off")
        if len(plan) == 0:
            return
        end = self.machine.move(plan.segments).wait(MOVE_TIMEOUT)
        if end is None or end.ended_by != "done":
            raise TouchOffError(f"stopped ({end.ended_by if end else 'timed out'})")

    def _set_zero(self, zero_mm: dict[int, float]) -> dict[int, float]:
        """Make each axis's machine mm in `zero_mm` its work zero in the active system; kept."""
        coordinates = self.machine.coordinates.model_copy(deep=True)
        for axis, mm in zero_mm.items():
            coordinates.set_position(0, self.config.axes[axis].name, mm, 0.0)
        self.machine.adopt_coordinates(coordinates)
        return zero_mm

    def _result(self, what: str, zero: dict[int, float]) -> TouchOffResult:
        names: dict[str, float] = {self.config.axes[i].name: mm for i, mm in zero.items()}
        return TouchOffResult(what, names, self.machine.coordinates.name)

    def _axis(self, name: str) -> int:
        names = self.config.axis_names
        if name.upper() not in names:
            raise TouchOffError(f"this machine has no {name.upper()} axis ({', '.join(names)})")
        return names.index(name.upper())

    def _radius(self, radius: float | None) -> float:
        return self.settings.tool_diameter / 2 if radius is None else radius

    def _check(self) -> None:
        if self._stopped.is_set():
            raise TouchOffError("stopped (HOLD), no zero set")
