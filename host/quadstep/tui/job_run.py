"""Running a job from the TUI: stream a planned job (quadstep.job.load_job), pause, halt.

The plan is streamed section by section: an M0 (or a move file's pause) ends
a section at rest, and the job waits there until resume(). halt() brings the
machine to rest with HOLD.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from itertools import accumulate
from pathlib import Path

from ..jog.motion import Motion, MotionEnd
from ..link import Link
from ..planner.plan import Plan


@dataclass(frozen=True)
class JobProgress:
    done: int  # segments completed
    total: int
    line: int  # source line (or move) being executed
    seconds_left: float
    paused_at: int | None  # line of the pause the job waits at


class JobRun:
    """One planned job on one link: run() blocks (call it from a worker thread)."""

    def __init__(self, link: Link, plan: Plan, decels: tuple[int, ...], path: Path) -> None:
        self.link = link
        self.plan = plan
        self.decels = decels
        self.path = path
        self._ticks = list(accumulate(plan.segments.n, initial=0))
        self._lock = threading.Lock()
        self._resume = threading.Event()
        self._halted: str | None = None
        self._motion: Motion | None = None
        self._offset = 0  # segments of the sections before the current one
        self._paused_at: int | None = None

    @property
    def progress(self) -> JobProgress:
        with self._lock:
            motion, offset, paused = self._motion, self._offset, self._paused_at
        done = offset + (motion.done if motion is not None else 0)
        total = len(self.plan)
        line = int(self.plan.segments.line[min(done, total - 1)])
        left = (self._ticks[-1] - self._ticks[done]) / self.plan.config.tick_hz
        return JobProgress(done, total, line, left, paused)

    def run(self) -> MotionEnd:
        """Stream every section; returns how the job ended (`done`, `stop`, or `error`)."""
        bounds = [index for index, _ in self.plan.pauses if 0 < index < len(self.plan)]
        lines = {index: line for index, line in self.plan.pauses}
        first = 0
        end: MotionEnd | None = None
        for last in [*bounds, len(self.plan)]:
            with self._lock:
                if self._halted:
                    break
                motion = Motion(self.link, self.plan.segments, self.decels, first=first, last=last)
                self._motion = motion
                self._offset = first
            end = motion.start().wait()
            assert end is not None
            if end.ended_by != "done" or last == len(self.plan):
                return end
            with self._lock:
                self._motion = None
                self._offset = last
                self._paused_at = lines.get(last)
            self._resume.wait()
            self._resume.clear()
            with self._lock:
                self._paused_at = None
            first = last
        if end is None or self._halted:
            status = self.link.status()
            return MotionEnd(self._halted or "stop", tuple(status.position[: self.plan.segments.axis_count]),
                             self._offset)
        return end

    def resume(self) -> bool:
        """Go on after a pause; False when the job is not paused."""
        with self._lock:
            if self._paused_at is None:
                return False
        self._resume.set()
        return True

    def halt(self, reason: str = "stop") -> None:
        """Bring the machine to rest (HOLD) and end the job."""
        with self._lock:
            self._halted = reason
            motion = self._motion
        self._resume.set()
        if motion is not None:
            motion.halt(reason)
