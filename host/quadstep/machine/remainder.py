"""What is left of a job held partway (a feed hold): the program from the move the hold interrupted
on, planned again from where the machine rests, so that it accelerates afresh and every remaining
move lands exactly. And what follows a pause (M0, a tool change) after the operator jogged or set a
work zero there: the rest of the program from where the machine stands, each move shifted by how its
work offset changed."""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import replace

from ..config import MachineConfig
from ..coordinates import SYSTEMS, WorkCoordinates
from ..planner.plan import Plan, plan_program
from ..planner.program import Item, LinearMove, Pause, Program, SetOutputs


def move_item(program: Program, config: MachineConfig, start: tuple[int, ...], move: int) -> int:
    """The index in program.items of the plan's move number `move` (counted as the planner counts
    them: moves too short for a step are not moves); len(items) when there is no such move."""
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


def rest_of(program: Program, first: int) -> Program:
    """`program` from its item `first` on, the outputs as they were there."""
    outputs = [item for item in program.items[:first] if isinstance(item, SetOutputs)][-1:]
    return replace(program, items=outputs + program.items[first:])


def remainder_program(program: Program, plan: Plan, held_segment: int) -> Program:
    """What is left of `program` (planned as `plan`) held during its segment `held_segment`: the
    interrupted move again, then everything after it."""
    # the first move whose segments end past the held one
    move = bisect_right(plan.move_ends, held_segment)
    return rest_of(program, move_item(program, plan.config, plan.start, move))


def plan_remainder(
    program: Program, plan: Plan, held_segment: int, rest: tuple[int, ...], label: str
) -> Plan:
    """The rest of `program` (planned as `plan`), held during its segment `held_segment`, from rest
    position `rest`: the interrupted move again, from where the machine stands, then everything
    after it."""
    return plan_program(remainder_program(program, plan, held_segment), plan.config, rest, label)


def shift_items(
    items: list[Item], before: WorkCoordinates, after: WorkCoordinates, axis_names: tuple[str, ...]
) -> list[Item]:
    """`items` with every move in a work system moved by how that system's offset went from `before`
    to `after` (moves in machine coordinates, G53 and G28/G30's, stay)."""
    deltas = {
        name: tuple(after.offset_in(k, a) - before.offset_in(k, a) for a in axis_names)
        for k, name in enumerate(SYSTEMS, start=1)
    }
    if not any(any(d) for d in deltas.values()):
        return items
    shifted: list[Item] = []
    for item in items:
        delta = deltas.get(item.system) if isinstance(item, LinearMove) else None
        if isinstance(item, LinearMove) and delta is not None and any(delta):
            item = replace(
                item,
                target=tuple(t + d for t, d in zip(item.target, delta)),
                offset=tuple(o + d for o, d in zip(item.offset or (0.0,) * len(delta), delta)),
            )
        shifted.append(item)
    return shifted


def carry_changes(
    coordinates: WorkCoordinates, before: WorkCoordinates, after: WorkCoordinates
) -> None:
    """What the operator changed from `before` to `after` (offsets, G92, the tool length) made to
    `coordinates` too."""
    offsets = [dict(o) for o in coordinates.offsets]
    for k, system in enumerate(offsets):
        for axis in {*before.offsets[k], *after.offsets[k]}:
            system[axis] = (
                system.get(axis, 0.0)
                + after.offsets[k].get(axis, 0.0)
                - before.offsets[k].get(axis, 0.0)
            )
    coordinates.offsets = offsets
    if after.g92 != before.g92 or after.g92_applied != before.g92_applied:
        coordinates.g92, coordinates.g92_applied = dict(after.g92), after.g92_applied
    if after.tlo != before.tlo:
        coordinates.tlo = after.tlo


def after_pause_program(
    program: Program,
    line: int,
    before: WorkCoordinates,
    after: WorkCoordinates,
    config: MachineConfig,
) -> Program:
    """The rest of `program` after its pause at `line`, with the work offsets the operator set there
    (`after`, where the program had `before`)."""
    where = next(
        i for i, item in enumerate(program.items) if isinstance(item, Pause) and item.line == line
    )
    outputs = [item for item in program.items[:where] if isinstance(item, SetOutputs)][-1:]
    items = shift_items(program.items[where + 1 :], before, after, config.axis_names)
    return replace(program, items=outputs + items)


def plan_after_pause(
    program: Program,
    line: int,
    rest: tuple[int, ...],
    before: WorkCoordinates,
    after: WorkCoordinates,
    config: MachineConfig,
    label: str,
) -> Plan:
    """The rest of `program` after its pause at `line`, from `rest`, with the work offsets set
    there."""
    return plan_program(
        after_pause_program(program, line, before, after, config), config, rest, label
    )
