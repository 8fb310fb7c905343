"""A job shown before it moves: its path in the path view, and in the log its size, bounding box
(work coordinates), planned time and what to look out for; Enter then runs it, Esc drops it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from textual.suggester import Suggester

from ..job import Job
from ..machine import Machine
from ..protocol import Capability
from ..toolpath import Toolpath

# listed at most, when completing a path (a directory with more shows the first in order)
COMPLETION_ENTRIES = 2000


@dataclass(frozen=True)
class Preview:
    """A job planned from `start` (step positions), waiting for Enter."""

    job: Job
    path: Path
    start: tuple[int, ...]
    toolpath: Toolpath
    source: list[str]


def preview_lines(preview: Preview, machine: Machine) -> list[str]:
    """What the log says of a job before it runs: the file, the box, the time, the warnings."""
    job, path = preview.job, preview.toolpath
    summary = job.summary()
    names = machine.config.axis_names
    lines = [
        f"job {preview.path}: {job.source_size}, {summary.moves} moves, "
        f"{summary.duration_s:.1f} s planned, {summary.distance_mm:.1f} mm"
    ]
    if path.work_box is not None:
        box = "  ".join(
            f"{n} {lo:.2f}…{hi:.2f}"
            for n, lo, hi in zip(names, path.work_box.low, path.work_box.high)
        )
        lines.append(f"  box ({job.coordinates.name}): {box}")
    lines += [f"  warning: {text}" for text in warnings(job, machine)]
    lines.append("  Enter runs it, Esc drops it")
    return lines


def warnings(job: Job, machine: Machine) -> list[str]:
    found = []
    pauses = job.summary().pauses
    if pauses:
        found.append(
            f"it stops for the operator at line(s) {', '.join(map(str, pauses))} (g goes on)"
        )
    if job.plan.outputs and not machine.identity.capabilities & Capability.OUTPUTS:
        found.append("it sets the spindle or coolant, and this firmware has no outputs: refused")
    if machine.config.homing_required and not machine.homed:
        found.append("the machine is not homed (homing_required): refused until h")
    return found


class PathSuggester(Suggester):
    """Completes a path typed: the first entry of its directory that starts with what follows the
    last `/` (a directory with a `/` after it)."""

    def __init__(self) -> None:
        super().__init__(use_cache=False, case_sensitive=True)

    async def get_suggestion(self, value: str) -> str | None:
        if not value:
            return None
        typed = Path(value).expanduser()
        folder, stem = (typed, "") if value.endswith("/") else (typed.parent, typed.name)
        try:
            entries = sorted(p for _, p in zip(range(COMPLETION_ENTRIES), folder.iterdir()))
        except OSError:
            return None
        for entry in entries:
            if (
                entry.name.startswith(stem)
                and entry.name != stem
                and not entry.name.startswith(".")
            ):
                rest = entry.name[len(stem) :] + ("/" if entry.is_dir() else "")
                return value + rest
        return None
