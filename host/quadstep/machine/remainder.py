"""What is left of a job held partway (a feed hold): the program from the move the hold interrupted on, planned
again from where the machine rests, so that it accelerates afresh and every remaining move lands exactly."""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import replace

from ..config import MachineConfig
from ..planner.plan import Plan, plan_program
from ..planner.program import LinearMove, Program


def move_item(program: Program, config: MachineConfig, start: tuple[int, ...], move: int) -> int:
    """The index in program.items of the plan's move number `move` (counted as the planner counts them: moves
    too short for a step are not moves); len(items) when there is no such move."""
    current, count = start, 0
    for index, item in enumerate(program.items):
        if not isinstance(item, LinearMove):
            continue
        target = config.to_steps(item.target)
        if target == current:
            continue
        if count == move:
            return index
        count += 1
        current = target
    return len(program.items)


def plan_remainder(program: Program, plan: Plan, held_segment: int, rest: tuple[int, ...], label: str) -> Plan:
    """The rest of `program` (planned as `plan`), held during its segment `held_segment`, from rest position
    `rest`: the interrupted move again, from where the machine stands, then everything after it."""
    move = bisect_right(plan.move_ends, held_segment)  # the first move whose segments end past the held one
    first = move_item(program, plan.config, plan.start, move)
    return plan_program(replace(program, items=program.items[first:]), plan.config, rest, label)
