"""GRBL's `Pn:` field: the board's inputs that are active, as GRBL letters them (P the probe, an
axis letter for either of its limit switches, R the abort button, H feed hold, S cycle start), in
GRBL's order."""

from __future__ import annotations

from collections.abc import Sequence

from ..protocol import Input

CONTROL_LETTERS = ((Input.ABORT, "R"), (Input.FEED_HOLD, "H"), (Input.CYCLE_START, "S"))


def pin_letters(active: int, axis_names: Sequence[str]) -> str:
    """The letters of the inputs set in `active` (an input mask), "" when none is."""

    def on(which: Input) -> bool:
        return bool(active >> which & 1)

    letters = "P" if on(Input.PROBE) else ""
    for axis, name in enumerate(axis_names[:4]):
        if on(Input.limit(axis)) or on(Input.limit(axis, max_end=True)):
            letters += name
    return letters + "".join(letter for which, letter in CONTROL_LETTERS if on(which))
