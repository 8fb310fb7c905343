"""Whether the lines queued at the front door hold a laser raster run (planner/raster_gcode.py:
G1 moves along X at one feed whose S changes, in laser mode), and whether the last of them may go on
with one. A raster row is burned as RASTER lines in a job of its own, planned whole, so its lines
are gathered before it runs and never added to a job that is running (executor.py)."""

from __future__ import annotations

from collections.abc import Iterable

from ..config import MachineConfig
from ..planner.program import Item, LinearMove, OutputState, SetOutputs
from ..planner.raster_gcode import MIN_RUN, candidate_step, lasing


class RasterWatch:
    """Fed the items of the lines as they are queued; `holds_run` once a run of them could be a
    raster (MIN_RUN moves, two powers or more), `growing` while the last of them may be part of
    one (a run of fewer moves, or of more powers: a longer one at one power is a cut, which an
    open job takes as it comes). Always False where the machine burns no rasters (no RASTER, not
    a laser, S-curves)."""

    def __init__(self, config: MachineConfig, takes_rasters: bool) -> None:
        self._config = config
        self._on = takes_rasters and config.spindle.laser and not config.jerk_limited
        self._at: tuple[float, ...] | None = None  # the last target: the next move starts there
        self._state: OutputState | None = None  # the outputs in force after the last item
        self._moves = 0  # moves of the run the last item belongs to
        self._feed: float | None = None
        self._forward = True
        self._powers: set[int] = set()
        self.holds_run = False

    @property
    def growing(self) -> bool:
        return self._on and 0 < self._moves and (self._moves < MIN_RUN or len(self._powers) > 1)

    def add(self, items: Iterable[Item]) -> None:
        for item in items:
            if isinstance(item, SetOutputs):
                self._state = item.state
            elif isinstance(item, LinearMove):
                self._move(item)
            else:
                self._moves = 0  # a dwell, a pause or a probe ends a run

    def clear(self) -> None:
        """The queued lines were taken: a run goes on only in lines still to come."""
        self.holds_run = False
        self._moves = 0

    def _move(self, move: LinearMove) -> None:
        at, self._at = self._at, move.target
        lit = lasing(self._state, self._config)
        step = candidate_step(move, at, lit) if at is not None else 0.0
        if step == 0.0:
            self._moves = 0
            return
        power = round(self._config.spindle.power(self._state.speed) / 257) if self._state else 0
        if self._moves and move.feed == self._feed and (step > 0) == self._forward:
            self._moves += 1
            self._powers.add(power)
        else:
            self._moves, self._feed, self._forward, self._powers = 1, move.feed, step > 0, {power}
        if self._on and self._moves >= MIN_RUN and len(self._powers) >= 2:
            self.holds_run = True
