"""G38.2–G38.5 in a job: a probing move, after which the job goes on from where the probe stopped.

What follows a probe often depends on where it touched (`G10 L20 P1 Z10` after `G38.2 Z-40`), so the
rest of the file is read again from the probe's rest position when the job gets there
(`ProbeMove.resume`), in the modal state the file had at the probe. Until then — to check the whole
job before it starts — it is read and planned as if the probe went all the way to its target (a
straight move after a stop, which the job never streams: it probes there instead).
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any

from ..planner.program import ProbeMove, Program
from .lines import code
from .words import GcodeError, Word

# What the interpreter carries from line to line (besides the position, which the probe decides).
MODAL = (
    "units",
    "absolute",
    "plane",
    "motion",
    "feed",
    "inverse_time",
    "deviation",
    "outputs",
    "tool",
    "coords",
)


def probe_move(
    interpreter: Any, word: Word, axes: dict[str, Word], line: int, no_feed: str
) -> None:
    """G38.x on `line` toward the axis words: a ProbeMove, able to read the rest of the file from
    any rest. `interpreter` is the GcodeInterpreter reading the file (which imports this module)."""
    name = f"G{code(word)}"
    if not axes:
        raise GcodeError(line, word.column, f"{name} needs an axis word: where to probe toward")
    if interpreter.feed is None:
        raise GcodeError(
            line, word.column, f"{name} needs a feed rate: no F on this line or before ({no_feed})"
        )
    target = interpreter._target(axes)
    if all(abs(t - p) < 1e-9 for t, p in zip(target, interpreter.position)):
        raise GcodeError(line, word.column, f"{name}: the target is where the machine already is")
    state = {key: copy.deepcopy(getattr(interpreter, key)) for key in MODAL}
    source = interpreter.source

    def resume(position_mm: Sequence[float]) -> Program:
        return read_rest(interpreter, source, line, state, position_mm)

    interpreter.program.items.append(
        ProbeMove(line, code(word) or "", tuple(target), interpreter.feed, resume=resume)
    )
    # planned as if it went all the way, for the checks
    interpreter._move(target, interpreter.feed, line)


def read_rest(
    like: Any, source: list[str], after: int, state: dict[str, object], position_mm: Sequence[float]
) -> Program:
    """The lines of `source` after line `after`, read from `position_mm` in the modal `state`."""
    interpreter = type(like)(
        like.axis_names, position_mm, like.arc_tolerance, like.skip_unsupported, state["coords"]
    )
    for key, value in state.items():
        if key != "coords":
            setattr(interpreter, key, copy.deepcopy(value))
    interpreter.source = source
    for number, text in enumerate(source[after:], start=after + 1):
        if not interpreter.feed_line(text, number):
            break
    return interpreter.program
