"""The console (MDI): one G-code line at a time, checked and planned whole from where the machine
stands, then run like a job. Units, G90/G91, the plane, the motion mode and the feed carry over from
one line to the next, as on a controller; work offsets are the machine's."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .config import MachineConfig
from .coordinates import WorkCoordinates
from .gcode.interpreter import GcodeInterpreter
from .job import Job
from .planner.plan import plan_program
from .planner.program import JobError

MODAL = ("units", "absolute", "plane", "motion", "feed")  # what a line leaves for the next
SOURCE = Path("MDI")


class Console:
    def __init__(self, config: MachineConfig) -> None:
        self.config = config
        self._modal: dict[str, object] = {}

    def plan(self, text: str, start: tuple[int, ...], coordinates: WorkCoordinates) -> Job:
        """The line as a job from step position `start`; raises JobError naming the fault, and then
        nothing of the line is kept (not even its modal words)."""
        try:
            return self.plan_lines([text], start, coordinates)
        except JobError as exc:
            raise JobError(f"MDI: {_without_line(str(exc))}") from None

    def plan_lines(
        self, lines: Sequence[str], start: tuple[int, ...], coordinates: WorkCoordinates
    ) -> Job:
        """A few lines (a macro) as one job, the modal state carried in and out as for a line;
        raises JobError naming the line at fault."""
        config = self.config
        interpreter = GcodeInterpreter(
            config.axis_names, config.to_mm(start), config.arc_tolerance, coordinates=coordinates
        )
        for name, value in self._modal.items():
            setattr(interpreter, name, value)
        for number, text in enumerate(lines, 1):
            interpreter.feed_line(text, number)
        plan = plan_program(interpreter.program, config, start, "MDI")
        self._modal = {
            name: getattr(interpreter, name) for name in MODAL if hasattr(interpreter, name)
        }
        return Job(path=SOURCE, program=interpreter.program, plan=plan, coordinates=coordinates)


def _without_line(message: str) -> str:
    """A fault in the one line typed, without its line number (the planner's or the reader's)."""
    for prefix in ("line 1: ", f"{SOURCE} 1: ", "line 1, "):
        if message.startswith(prefix):
            return message.removeprefix(prefix)
    return message
