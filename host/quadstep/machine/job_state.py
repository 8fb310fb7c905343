"""The states of a running job and the transitions between them, with no I/O: the job runner
(job.py) steps this model at every turn of the job, and everything that shows a job (the CLI, the
TUI) reads its state.

    STREAMING ──section done, pause next──▶ PAUSED ──resume──▶ RESUMING ──▶ STREAMING
        │  ▲                                  │
        │  └──override planned── OVERRIDING ◀─┘ (from STREAMING only)
        ├──feed hold, at rest──▶ HELD ──resume──▶ RESUMING
        ├──queue ran dry, at rest──▶ STARVED ──(by itself)──▶ RESUMING
        ├──G38.x next──▶ PROBING ──probed──▶ RESUMING
        ├──an open job's lines came after its end was sent, at rest──▶ RESUMING
        └──last section done──▶ DONE          any state ──halt──▶ STOPPED, ──error──▶ FAILED

An open job (a sender's stream, JobRun.extend) plans the lines it is given onto what is not yet sent
while STREAMING; with nothing left to run and nothing given it ends DONE: a sender's lines that come
later start a new job, and the machine waits for them at rest, with no job.

A job waits for nobody but the operator in PAUSED and HELD; STARVED, RESUMING and OVERRIDING are
passed through by the runner on its own (the rest planned again from where the machine stands or
from the first move not yet sent).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum


class JobState(Enum):
    STREAMING = "streaming"  # a stretch of the plan is on its way to the board
    # at rest at an M0, M1 or tool change of the program, waiting for the operator
    PAUSED = "paused"
    HELD = "held"  # at rest after a feed hold, waiting for the operator
    # the board ran dry and braked to rest: the rest is planned again, without the operator
    STARVED = "starved"
    PROBING = "probing"  # the machine probes for a G38.x of the program
    # the rest planned again at a new feed override while the board keeps moving
    OVERRIDING = "overriding"
    RESUMING = "resuming"  # what is left planned again from where the machine rests
    DONE = "done"
    STOPPED = "stopped"  # halted by the user (HOLD to rest)
    FAILED = "failed"  # an error: the link, the board's alarm, a plan that could not be made

    @property
    def final(self) -> bool:
        return self in FINAL

    @property
    def waiting(self) -> bool:
        """At rest until the operator says go on."""
        return self in (JobState.PAUSED, JobState.HELD)

    @property
    def label(self) -> str:
        """How the CLI and the TUI name it."""
        return LABELS[self]


FINAL = frozenset({JobState.DONE, JobState.STOPPED, JobState.FAILED})

LABELS = {
    JobState.STREAMING: "running",
    JobState.PAUSED: "paused",
    JobState.HELD: "feed hold",
    JobState.STARVED: "starved, going on",
    JobState.PROBING: "probing",
    JobState.OVERRIDING: "running (feed override)",
    JobState.RESUMING: "resuming",
    JobState.DONE: "done",
    JobState.STOPPED: "stopped",
    JobState.FAILED: "failed",
}

S = JobState
TRANSITIONS: dict[JobState, frozenset[JobState]] = {
    # RESUMING from STREAMING: an open job's lines that came after the board was sent its end
    S.STREAMING: frozenset(
        {S.STREAMING, S.PAUSED, S.HELD, S.STARVED, S.PROBING, S.OVERRIDING, S.RESUMING, S.DONE}
    ),
    S.OVERRIDING: frozenset({S.STREAMING, S.HELD, S.STARVED}),
    S.PAUSED: frozenset({S.RESUMING, S.STREAMING, S.PROBING, S.DONE}),
    S.HELD: frozenset({S.RESUMING}),
    S.STARVED: frozenset({S.RESUMING}),
    S.PROBING: frozenset({S.RESUMING}),
    S.RESUMING: frozenset({S.STREAMING, S.PAUSED, S.PROBING, S.DONE}),
    S.DONE: frozenset(),
    S.STOPPED: frozenset(),
    S.FAILED: frozenset(),
}
# From any state not final: the user's stop, or an error.
ALWAYS = frozenset({S.STOPPED, S.FAILED})


@dataclass(frozen=True)
class JobProgress:
    """Where a job is, as the CLI and the TUI show it."""

    done: int  # segments completed
    total: int
    line: int  # source line (or move) being executed
    seconds_left: float
    paused_at: int | None  # line of the pause or feed hold the job waits at
    state: JobState = JobState.STREAMING
    starvations: int = 0  # times the board ran dry and the job went on


class TransitionError(RuntimeError):
    """A step the model does not allow: a fault of the runner, never of the user's input."""


class JobStates:
    """The state of one job, changed only through `enter`; thread-safe. `line` is the program line
    the state concerns (the pause's, the hold's), `starvations` counts the times the board ran dry
    and the job went on."""

    def __init__(self, on_change: Callable[[JobState], None] | None = None) -> None:
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)
        self._state = JobState.STREAMING
        self._line: int | None = None
        self.starvations = 0
        self.history: list[JobState] = [JobState.STREAMING]
        self._on_change = on_change

    @property
    def state(self) -> JobState:
        with self._lock:
            return self._state

    @property
    def line(self) -> int | None:
        """The line of the pause or hold the job waits at, else None."""
        with self._lock:
            return self._line if self._state.waiting else None

    def snapshot(self) -> tuple[JobState, int | None]:
        with self._lock:
            return self._state, (self._line if self._state.waiting else None)

    def enter(self, state: JobState, line: int | None = None) -> JobState:
        """Go to `state` (TransitionError where the model has no such step); returns the state
        left."""
        with self._lock:
            left = self._set(state, line)
        if self._on_change is not None:
            self._on_change(state)
        return left

    def leave(self, waiting: JobState, to: JobState) -> bool:
        """Go to `to` if the job is in `waiting` now, as one step (a resume that meets no pause does
        nothing)."""
        with self._lock:
            if self._state is not waiting:
                return False
            self._set(to, None)
        if self._on_change is not None:
            self._on_change(to)
        return True

    def _set(self, state: JobState, line: int | None) -> JobState:
        left = self._state
        if left.final or (state not in TRANSITIONS[left] and state not in ALWAYS):
            raise TransitionError(f"a job cannot go from {left.value} to {state.value}")
        self._state, self._line = state, line
        if state is JobState.STARVED:
            self.starvations += 1
        self.history.append(state)
        self._changed.notify_all()
        return left

    def wait_for(self, predicate: Callable[[JobState], bool], timeout: float | None = None) -> bool:
        with self._lock:
            return self._changed.wait_for(lambda: predicate(self._state), timeout)
