"""The machine's backlash: its band, the take-ups in what it streams, and the positions that exclude
them.

Every program the machine runs goes through the compensation stage (backlash/compensate.py) with the
band as it stands; when the program ends the band is where the motors left it — at the end of the
plan, or, after a stop, where the stop found it (a take-up cut short leaves the motor inside the
band, and the next motion takes up the rest). Positions shown while a program runs follow the band
tick by tick.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

from ..backlash.band import Band, BandAxis
from ..backlash.base import from_arrays, from_items
from ..backlash.compensate import Compensated, compensate, unchanged
from ..config import MachineConfig
from ..kernel.cubic_chain import CubicChain
from ..kernel.engine_model import predict
from ..planner.plan import Plan
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from ..protocol import CubicSegment, Segment


@dataclass(frozen=True)
class Running:
    compensated: Compensated
    motor: tuple[int, ...]  # the motors when it began
    tick: int  # the motion tick it began at


class TakeUps:
    """One machine's band and the compensated program running on it (thread-safe)."""

    def __init__(self, config: MachineConfig, band: Band | None = None) -> None:
        self.config = config
        self._lock = threading.Lock()
        self._band = band if band is not None else Band.of(config)
        self._running: Running | None = None

    @property
    def band(self) -> Band:
        with self._lock:
            return self._band

    @property
    def active(self) -> bool:
        return self.band.active

    def reset(self, band: Band | None = None) -> None:
        with self._lock:
            self._band = band if band is not None else Band.of(self.config)
            self._running = None

    def compensate(
        self,
        segments: SegmentArrays | Stream,
        pauses: Sequence[tuple[int, int]] = (),
        band: Band | None = None,
        entry: CubicChain | None = None,
    ) -> Compensated:
        """`segments` (planned: quadratic arrays, or a jerk-limited plan's cubic stream) with their
        take-ups, from the band as it stands (or `band`); `entry`: the firmware's chain where
        quadratic arrays go on from a stream before them (None: from rest)."""
        band = self.band if band is None else band
        if not band.active and isinstance(segments, (SegmentArrays, Stream)):
            return unchanged(segments, band, pauses, entry)  # no backlash: nothing to take up
        base = (
            from_arrays(segments, entry)
            if isinstance(segments, SegmentArrays)
            else from_items(segments, segments.axis_count)
        )
        return compensate(base, self.config, band, pauses=list(pauses))

    def compensate_items(
        self, items: Sequence[Segment | CubicSegment], axis_count: int
    ) -> Compensated:
        return compensate(from_items(items, axis_count), self.config, self.band)

    def begin(self, compensated: Compensated, motor: Sequence[int], tick: int) -> None:
        with self._lock:
            self._running = Running(compensated, tuple(motor), tick)

    def swap(self, compensated: Compensated, ticks: int = 0, motor: Sequence[int] = ()) -> None:
        """The running program goes on as `compensated`, which begins as it did (a job's tail
        planned again), or `ticks` motion ticks and `motor` steps into it (a job that let go of
        what ran: machine/rebase.py)."""
        with self._lock:
            running = self._running
            if running is not None:
                moved = tuple(m + d for m, d in zip(running.motor, motor)) or running.motor
                self._running = Running(compensated, moved, running.tick + ticks)

    def end(self, rest: Sequence[int], tick: int | None, done: bool) -> None:
        """The program ended: `rest` the motors, `tick` the motion tick its motion stopped at (a
        hold's, an alarm's; None: not known), `done` when every segment ran."""
        with self._lock:
            running, self._running = self._running, None
            if running is None:
                return
            count = len(self._band.axes)
            moved = [r - m for r, m in zip(rest[:count], running.motor)]
            comp = running.compensated
            if done:
                self._band = comp.band_end
            elif tick is not None:
                self._band = comp.band_at(tick - running.tick, moved)
            # where inside the band each motor stopped is not known: the next motion adopts its side
            else:
                self._band = Band(
                    tuple(BandAxis(a.size, None, a.offset()) for a in comp.band_start.axes)
                )

    def moved_raw(self, segments: Sequence[Segment | CubicSegment], done: bool) -> None:
        """Raw segments (not compensated) moved the motors: follow them through the band."""
        with self._lock:
            band = self._band
            if not band.active:
                return
            if not done:
                self._band = Band(tuple(BandAxis(a.size, None, a.offset()) for a in band.axes))
                return
            steps = predict(segments, axis_count=max(len(band.axes), 1)).steps
            for axis in range(len(band.axes)):
                band = band.with_axis(
                    axis, band.axes[axis].moved(int(s) for s in steps[steps[:, 1] == axis, 2])
                )
            self._band = band

    def moved_straight(self, deltas: Sequence[int]) -> None:
        """Each motor moved `deltas` steps in one straight motion, without take-ups."""
        with self._lock:
            band = self._band
            for axis, delta in enumerate(deltas[: len(band.axes)]):
                band = band.with_axis(axis, band.axes[axis].monotone(delta))
            self._band = band

    def set_axis(self, axis: int, state: BandAxis) -> None:
        with self._lock:
            self._band = self._band.with_axis(axis, state)

    def position(self, motor: Sequence[int], tick: int | None = None) -> tuple[int, ...]:
        """The positions shown for these motors: at rest, or `tick` (a motion tick) into the running
        program."""
        with self._lock:
            band, running = self._band, self._running
        if running is not None and tick is not None:
            band = running.compensated.band_at(tick - running.tick)
        return band.to_position(motor)

    def motor(self, position: Sequence[int]) -> tuple[int, ...]:
        """The motor counts that show `position` (at rest)."""
        return self.band.to_motor(position)


@dataclass(frozen=True)
class StreamPlan:
    """A planned job as it is streamed: the compensated segments and where the job pauses in
    them."""

    config: MachineConfig
    segments: Stream
    pauses: list[tuple[int, int]]
    compensated: Compensated
    base: Plan  # as planned

    def __len__(self) -> int:
        return len(self.segments)

    @property
    def duration_s(self) -> float:
        return self.segments.ticks / self.config.tick_hz


__all__ = ["StreamPlan", "TakeUps"]
