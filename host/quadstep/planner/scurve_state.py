"""Where a jerk-limited plan may go on from when lines are added after its end: the S-curve
planner's state at move boundaries from its settled moves on (planner/scurve_rest.py). The
acceleration is 0 at every junction, so the state where a move begins is all the moves after it
need. The settled boundary loses nothing (more lines change no move before it); a later one keeps
the moves before it as planned, slowing towards the end they had, so the machine slows there and
goes on without a stop: kept for when the settled boundary was sent already."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from ..kernel.cubic_chain import CubicChain
from .moves import MoveTable

# states kept per plan: the settled boundary's and those of the moves after it
KEPT_STATES = 64


@dataclass(frozen=True)
class ScurveState:
    """The planner where move `move` of its plan begins, before the stops in front of it, and the
    plan's figures so far. `segments`: the plan's segments before it; `distance_mm`: the length of
    its moves."""

    move: int
    segments: int
    chain: CubicChain
    position: tuple[int, ...]
    speed: float
    peak: tuple[int, ...]
    max_landing: int
    corrections: int
    distance_mm: float


class Planner(Protocol):
    """The S-curve planner (planner/scurve.py), as a keeper asks it for its state."""

    def state(self, move: int, distance_mm: float) -> ScurveState: ...


class StateKeeper:
    """Takes the planner's state before each move of `table` from move `settled` of the plan on
    (`first`: the plan's moves before the table's; `distance_mm` their length)."""

    def __init__(
        self, table: MoveTable, settled: int, first: int = 0, distance_mm: float = 0.0
    ) -> None:
        self.table, self.settled, self.first = table, settled, first
        self.distance_mm = distance_mm
        self.states: list[ScurveState] = []

    def before(self, planner: Planner, k: int) -> None:
        """Move k of the table is next."""
        move = self.first + k
        if not self.settled <= move < self.settled + KEPT_STATES:
            return
        if not self.states:  # the moves of the table before it
            self.distance_mm += float(sum(self.table.length[:k]))
        self.states.append(planner.state(move, self.distance_mm))
        self.distance_mm += self.table.length[k]

    def end(self, planner: Planner) -> tuple[ScurveState, ...]:
        """The states kept; where the table ends when no move comes after the settled ones."""
        if not self.states:
            length = float(sum(self.table.length))
            self.states.append(
                planner.state(self.first + len(self.table), self.distance_mm + length)
            )
        return tuple(self.states)
