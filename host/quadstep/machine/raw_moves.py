"""Straight moves of one axis by whole steps, without take-ups, for routines that measure the
backlash.

A measurement must see the backlash, so its moves go out as planned (no take-up) and at rest the
band follows each motor as it moved: every move is one straight motion, so its deceleration after an
input's edge goes on the same way and the band's state after it is exact (band.py).
"""

from __future__ import annotations

from ..kernel.fixed import MAX_AXES
from ..link import until_input
from ..planner.plan import plan_program
from ..planner.program import LinearMove, Program
from ..protocol import Input, InputChange, Probe, ProbeMissed, Segment
from ..protocol.wire import four_axes
from .homing import TIMEOUT, unbounded
from .machine import Machine


class RawMoves:
    """Moves of a held machine (inside a procedure) by steps; `motor` is where its motors stand."""

    def __init__(self, machine: Machine, feed: float) -> None:
        self.machine = machine
        self.link = machine.link
        self.config = unbounded(machine.config)  # a measurement goes where the user put the target
        self.feed = feed
        self.count = self.link.axis_count
        self.motor = list(self.link.status().position[: self.count])
        self.decel = four_axes(list(machine.decels) + [0] * (MAX_AXES - len(machine.decels)))

    def segments(self, axis: int, steps: int, feed: float | None = None) -> list[Segment]:
        start = tuple(self.motor[: len(self.config.axes)])
        target = list(start)
        target[axis] += steps
        move = LinearMove(line=1, target=self.config.to_mm(tuple(target)), feed=feed or self.feed)
        plan = plan_program(Program(items=[move], lines=1), self.config, start)
        return plan.quadratic_segments()

    def move(self, axis: int, steps: int, feed: float | None = None) -> None:
        """`steps` (signed) along `axis`, to rest."""
        if steps == 0:
            return
        stream = self.link.generation  # a hold from elsewhere (the feed hold button) ends the move
        for segment in self.segments(axis, steps, feed):
            self.link.send(segment, TIMEOUT, stream)
        self.link.wait_idle(TIMEOUT, stream)
        self._rested()

    def until(
        self, axis: int, steps: int, which: Input, level: int, feed: float | None = None
    ) -> int | None:
        """Up to `steps` along `axis` until `which` reaches `level`: the motor's latched step there
        (None: the move ended without the edge)."""
        end = until_input(
            self.link,
            Probe(input=which, level=level, decel=self.decel),
            self.segments(axis, steps, feed),
            TIMEOUT,
        )
        self._rested()
        return (
            end.position[axis]
            if isinstance(end, InputChange)
            else None
            if isinstance(end, ProbeMissed)
            else None
        )

    def _rested(self) -> None:
        before = self.motor
        self.motor = list(self.link.status().position[: self.count])
        self.machine.standing.raw_moved(before, self.motor)


__all__ = ["RawMoves"]
