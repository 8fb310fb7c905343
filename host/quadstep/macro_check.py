"""Checks a configuration's macros (`[[macros]]`) when it is loaded: each G-code line read as the
console reads it, a bad one named with its macro and line; nothing runs."""

from __future__ import annotations

from .config import MachineConfig
from .gcode.interpreter import GcodeInterpreter
from .planner.program import JobError

# A macro may rely on the console's feed (modal state carries into it): a placeholder for the check.
CHECK_FEED = 1.0  # mm/s


def macro_problems(config: MachineConfig, source: str) -> list[str]:
    """One line per bad G-code line or repeated key: `FILE: macros[1] (probe Z) line 2: …`."""
    problems = []
    keys: dict[str, str] = {}
    for i, macro in enumerate(config.macros):
        where = f"{source}: macros[{i}] ({macro.name})"
        if macro.key in keys:
            problems.append(f"{where}: key {macro.key!r} is {keys[macro.key]}'s already")
        keys.setdefault(macro.key, macro.name)
        interpreter = GcodeInterpreter(
            config.axis_names, (0.0,) * len(config.axes), config.arc_tolerance
        )
        interpreter.feed = CHECK_FEED
        for number, line in enumerate(macro.gcode, 1):
            try:
                interpreter.feed_line(line, number)
            except JobError as exc:
                problems.append(f"{where} line {number}: {_reason(str(exc), number)}")
                break
    return problems


def _reason(message: str, number: int) -> str:
    return message.removeprefix(f"line {number}: ").removeprefix(f"line {number}, ")
