"""The machine layer: one object per connected machine, between the user interfaces and the link.

A Machine owns the link, the configuration, the one firmware/configuration
agreement check, the exact step position and the HOLD decelerations; it runs
programs (jobs, jogs, raw segments: Motion and JobRun) one at a time and
stops them — `hold()` is the user's stop, `emergency_stop()` the immediate
one. The CLI, the TUI and jogging use it and nothing below it.
"""

from .errors import MachineError
from .job import JobProgress, JobRun
from .job_state import JobState
from .machine import Machine, Running
from .motion import Motion, MotionEnd
from .state import StateError, load_state, save_state, state_path
from .target import Target, open_machine, start_emulator

__all__ = [
    "JobProgress",
    "JobRun",
    "JobState",
    "Machine",
    "MachineError",
    "Motion",
    "MotionEnd",
    "Running",
    "StateError",
    "Target",
    "load_state",
    "open_machine",
    "save_state",
    "start_emulator",
    "state_path",
]
