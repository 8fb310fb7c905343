"""Where a job's next leg begins: what is left of its program, to be planned again from where the
machine rests — after a stop that kept the rest of the job (a feed hold, the board running dry),
after a probe of the program, after a pause where the operator moved the machine or changed the work
offsets — and where each leg's moves end in the stream the board counts (what the journal keeps)."""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Sequence

from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..planner.plan import Plan
from ..planner.program import Pause, ProbeMove, Program
from .move_items import MoveItems
from .remainder import after_pause_program, carry_changes, remainder_program
from .restream import Restream
from .takeups import StreamPlan


def base_plan(plan: Plan | StreamPlan) -> Plan:
    """The plan as planned (a stream's without its take-ups)."""
    return plan.base if isinstance(plan, StreamPlan) else plan


def stream_move_ends(plan: Plan | StreamPlan) -> list[int]:
    """Where each move of the plan ends in the stream the board counts (take-ups included)."""
    if not isinstance(plan, StreamPlan):
        return list(plan.move_ends)
    origin = plan.segments.origin
    return [bisect_left(origin, end) for end in plan.base.move_ends]


def rest_after_stop(
    program: Program, plan: Plan | StreamPlan, stopped_at: int, items: MoveItems | None = None
) -> Program:
    """What is left of `program` (streamed as `plan`) stopped during its stream segment
    `stopped_at`: the move it was in again, then everything after it (`items`: where the plan's
    moves are in the program, kept from before)."""
    held = plan.segments.origin_of(stopped_at) if isinstance(plan, StreamPlan) else stopped_at
    if items is None:
        return remainder_program(program, base_plan(plan), held)
    move = bisect_right(base_plan(plan).move_ends, held)  # the first move ending past it
    return items.rest_of(program, items.item_of(program, move))


def rest_after_probe(program: Program, probe: ProbeMove, rest_mm: Sequence[float]) -> Program:
    """The rest of `program` read again from where its probe stopped (`rest_mm`, machine mm); the
    work coordinates it leaves are the caller's object, updated in place."""
    assert probe.resume is not None
    rest = probe.resume(rest_mm)
    kept = program.coordinates
    if kept is not None and rest.coordinates is not None:
        for name in type(kept).model_fields:
            setattr(kept, name, getattr(rest.coordinates, name))
        rest.coordinates = kept
    return rest


def rest_after_pause(
    program: Program,
    pause: Pause,
    before: WorkCoordinates,
    after: WorkCoordinates,
    config: MachineConfig,
) -> Program:
    """The rest of `program` after `pause`, where the work offsets went from `before` to `after`
    meanwhile."""
    rest = after_pause_program(program, pause.line, before, after, config)
    if program.coordinates is not None:
        carry_changes(program.coordinates, before, after)
    return rest


class PauseOffer:
    """At a pause of the program the machine works in the program's work coordinates there, so that
    a zero the operator sets at the pause lands in them; where nothing changes, the machine's own
    come back."""

    def __init__(self, program: WorkCoordinates, restream: Restream) -> None:
        self.program = program
        self.restream = restream
        self.previous = restream.coordinates()
        restream.adopt(program.model_copy(deep=True))  # in memory only: kept where a zero is set

    def settle(self, interrupted: bool, halted: bool) -> WorkCoordinates | None:
        """As the job goes on (or is halted): the coordinates the operator left
        where the rest must be planned again in them (they changed, or another program moved the
        machine), else None."""
        after = self.restream.coordinates()
        if not halted and (interrupted or after != self.program):
            return after
        if after == self.program:
            self.restream.adopt(self.previous)
        return None
