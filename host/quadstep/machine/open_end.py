"""The open end of a job that a stream of lines extends while it runs (a G-code sender's, through
`quadstep grbl`): the lines received while the job runs wait here until the job's thread plans them
onto what is not yet sent (job.py), and the end of the plan — where it comes to rest at the last
line received — is kept back from the board while more lines may come (docs/PLANNER.md,
"Streaming")."""

from __future__ import annotations

import threading
from bisect import bisect_left
from collections.abc import Sequence
from dataclasses import replace

from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..planner.lookahead import settled_moves as settled_junctions
from ..planner.plan import Plan
from ..planner.program import Item, Program

# The board is sent the kept-back end only while it holds less than this much motion before it (and
# less than half its queue): lines arriving in the meantime are planned in its place. A host held up
# longer than this lets the board run dry (an underrun's stop, then the job goes on from rest).
FLOOR_S = 0.25
# Lines added are planned onto the job once this many items wait (each addition plans the stop at
# the end again), or once that stop is within LEAD_S of being sent (the floor, and this).
BATCH_ITEMS = 48
LEAD_S = 0.08
# The kept-back end: the longest stop any axis makes from its top speed, with this margin (a stop
# along several moves may take a little longer than along one), plus the floor.
STOP_MARGIN = 1.5


def longest_stop_s(config: MachineConfig) -> float:
    """The longest stop any axis makes from its top speed."""
    return max(axis.max_speed / axis.max_accel for axis in config.axes)


def kept_back_s(config: MachineConfig) -> float:
    """The end of a running open job kept back from the board, in seconds of its motion."""
    return STOP_MARGIN * longest_stop_s(config) + FLOOR_S


class OpenEnd:
    """Lines taken while the job runs (thread-safe). Once closed it takes no more and the job's
    plan runs to its end; the lines taken before go on as planned."""

    def __init__(self, config: MachineConfig, floor_s: float = FLOOR_S) -> None:
        hz = config.tick_hz
        self.floor_ticks = round(floor_s * hz)
        self.reserve_ticks = round(STOP_MARGIN * longest_stop_s(config) * hz) + self.floor_ticks
        self.batch = BATCH_ITEMS
        self.lead_ticks = round(LEAD_S * hz)
        self._lock = threading.Lock()
        self._open = True
        self._items: list[Item] = []
        self._lines: int | None = None
        self._coordinates: WorkCoordinates | None = None

    @property
    def open(self) -> bool:
        with self._lock:
            return self._open

    @property
    def pending(self) -> int:
        """Items taken, not yet in the job's program."""
        with self._lock:
            return len(self._items)

    def add(self, items: Sequence[Item], lines: int, coordinates: WorkCoordinates | None) -> bool:
        """Take `items` (the program's lines now `lines`, its work coordinates after them
        `coordinates`); False once closed."""
        with self._lock:
            if not self._open:
                return False
            self._items.extend(items)
            self._lines, self._coordinates = lines, coordinates
            return True

    def close(self) -> None:
        with self._lock:
            self._open = False

    def merge(self, program: Program) -> Program:
        """`program` with the items taken since the last merge after its own."""
        with self._lock:
            items, self._items = self._items, []
            lines, coordinates = self._lines, self._coordinates
        if not items:
            return program
        return replace(
            program,
            items=[*program.items, *items],
            lines=lines if lines is not None else program.lines,
            coordinates=coordinates if coordinates is not None else program.coordinates,
        )

    def go_on(self, unplanned: bool) -> bool:
        """The job ran everything it planned: True when there is more (taken, or in the program
        and not planned), else the job closes and ends."""
        with self._lock:
            if self._items or unplanned:
                return True
            self._open = False
            return False

    def kept_back(self, ticks: Sequence[int]) -> int | None:
        """The first segment of the end kept back, from the plan's cumulative ticks (None when
        closed: everything is sent)."""
        with self._lock:
            if not self._open:
                return None
        return bisect_left(ticks, ticks[-1] - self.reserve_ticks)


def settled_moves(plan: Plan) -> int:
    """The moves of `plan` that lines added after its end leave as planned (planner/lookahead.py);
    for a jerk-limited plan, those before the first of its S-curve planner's kept states, which more
    lines go on from (planner/scurve_state.py)."""
    if len(plan.junctions) <= plan.moves:
        return 0  # not made by plan_program: everything again
    if plan.scurve_states:
        return plan.scurve_states[0].move
    return settled_junctions(plan.junctions, plan.moves)
