"""The coordinate words of a line: G54–G59, G10 L2/L20, G92 and G92.1–G92.3, G28.1/G30.1 (on
WorkCoordinates).

Values are in program units (G20/G21) and absolute whatever G90/G91 says,
as in GRBL and LinuxCNC. P selects a system: 0 the active one, 1 … 6 G54 … G59.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..coordinates import SYSTEMS, WorkCoordinates
from .words import GcodeError, Word


def select_system(coords: WorkCoordinates, word: Word) -> None:
    """G54 … G59."""
    coords.system = int(word.value) - 53


def g10(
    coords: WorkCoordinates,
    g: Word,
    axes: dict[str, Word],
    values: dict[str, Word],
    line: int,
    position: Sequence[float],
    axis_names: Sequence[str],
    units: float,
) -> None:
    """G10 L2 Pn (set the offset of system n) and G10 L20 Pn (make the current position read the
    values)."""
    level, system = values.get("L"), values.get("P")
    if level is None or level.value not in (2, 20):
        where = level or g
        shown = f"'{level.text}' is" if level is not None else "G10 without L is"
        raise GcodeError(
            line, where.column, f"{shown} not supported: G10 L2 and G10 L20 set work offsets"
        )
    if system is None or system.value not in range(len(SYSTEMS) + 1):
        where = system or g
        raise GcodeError(
            line,
            where.column,
            f"G10 L{level.value:g} needs P0 … P{len(SYSTEMS)} "
            f"(0: the active system, 1 … {len(SYSTEMS)}: G54 … G59)",
        )
    if "R" in values:
        raise GcodeError(
            line,
            values["R"].column,
            f"'{values['R'].text}': rotated coordinate systems are not supported",
        )
    if not axes:
        raise GcodeError(line, g.column, "G10 needs at least one axis word")
    for letter, w in axes.items():
        i = list(axis_names).index(letter)
        if level.value == 2:
            coords.set_offset(int(system.value), letter, w.value * units)
        else:
            coords.set_position(int(system.value), letter, position[i], w.value * units)


def g92(
    coords: WorkCoordinates,
    g: Word,
    key: str,
    axes: dict[str, Word],
    line: int,
    position: Sequence[float],
    axis_names: Sequence[str],
    units: float,
) -> None:
    """G92 (the current position reads the values given), G92.1 (clear), G92.2 (suspend), G92.3
    (restore)."""
    if key != "92":
        if axes:
            first = min(axes.values(), key=lambda w: w.column)
            raise GcodeError(line, first.column, f"'{first.text}': G{key} takes no axis words")
        {"92.1": coords.clear_g92, "92.2": coords.suspend_g92, "92.3": coords.restore_g92}[key]()
        return
    if not axes:
        raise GcodeError(line, g.column, "G92 needs at least one axis word")
    for letter, w in axes.items():
        coords.set_g92(letter, position[list(axis_names).index(letter)], w.value * units)


def store(
    coords: WorkCoordinates,
    key: str,
    axes: dict[str, Word],
    line: int,
    position: Sequence[float],
    axis_names: Sequence[str],
) -> None:
    """G28.1 / G30.1: remember where the machine is (machine coordinates)."""
    if axes:
        first = min(axes.values(), key=lambda w: w.column)
        raise GcodeError(line, first.column, f"'{first.text}': G{key} takes no axis words")
    coords.store(28 if key == "28.1" else 30, axis_names, position)
