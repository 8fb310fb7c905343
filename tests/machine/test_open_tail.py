"""What an addition to an open job plans again: only the moves from the stop at the plan's end on
(settled_moves), found in the program without reading it from its start (MoveItems), going on from
a boundary summed back from the plan's end; and a stream without take-ups built at once."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from quadstep.backlash.band import Band
from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.machine.move_items import MoveItems
from quadstep.machine.open_end import settled_moves
from quadstep.machine.override import boundary_at, feeds_at, replan_from
from quadstep.machine.remainder import move_item, rest_of
from quadstep.machine.takeups import TakeUps
from quadstep.planner.plan import plan_program
from quadstep.planner.program import Program
from quadstep.planner.stream import Stream

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def chords(count: int, length_mm: float = 0.05) -> str:
    """Chords of a circle, a zero-length move and an output change among them."""
    out = ["G21 G90 G94 F2400", "G0 X70 Y50"]
    for k in range(1, count + 1):
        a = k * length_mm / 20.0
        out.append(f"G1 X{50 + 20 * math.cos(a):.4f} Y{50 + 20 * math.sin(a):.4f}")
        if k % 97 == 0:
            out.append(out[-1])  # too short for a step: not a move
        if k % 151 == 0:
            out.append("M3 S1000")
    return "\n".join(out) + "\n"


def program_of(text: str) -> Program:
    return parse_gcode(text, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)


def test_move_items_find_what_reading_from_the_start_finds() -> None:
    whole = program_of(chords(600))
    start = (0, 0, 0)
    found = MoveItems(CONFIG, start)
    for size in (200, 450, len(whole.items)):  # the program growing at its end
        program = replace(whole, items=whole.items[:size])
        for move in (0, 1, 96, 97, 150, 151, 152, 300, 10_000):
            assert found.item_of(program, move) == move_item(program, CONFIG, start, move)
        for first in (0, 1, 153, 160, 302, 440, size):
            assert found.rest_of(program, first) == rest_of(program, first)
    other = program_of("G1 X1 F600\nM3 S100\nG1 X2\nG1 X3\n")  # another program: read again
    assert found.item_of(other, 1) == move_item(other, CONFIG, start, 1) == 2
    assert found.rest_of(other, 3) == rest_of(other, 3)


def test_moves_before_the_settled_ones_are_planned_the_same_with_more_lines() -> None:
    head, more = program_of(chords(300)), program_of(chords(420))
    plan, longer = plan_program(head, CONFIG), plan_program(more, CONFIG)
    settled = settled_moves(plan)
    assert 0 < settled < plan.moves - 10  # the stop at the end: a stretch of moves, not all
    assert longer.junctions[:settled] == plan.junctions[:settled]
    assert list(longer.junctions[settled : plan.moves]) != list(plan.junctions[settled:-1])
    end = plan.move_ends[settled - 1]
    for name in ("n", "axes", "v0", "vn", "r"):
        count = end * (len(CONFIG.axes) if name in ("v0", "vn", "r") else 1)
        assert getattr(longer.segments, name)[:count] == getattr(plan.segments, name)[:count]


def test_the_boundary_summed_back_from_the_end_is_the_one_summed_from_the_start() -> None:
    program = program_of(chords(400))
    plan = plan_program(program, CONFIG, (120, -40, 7))
    assert plan.end_ideal2
    joined = replan_from(program, plan, 250, feeds_at(100), "line")  # the tail planned again, joined
    for each in (plan, joined):
        from_start = replace(each, end_ideal2=())
        for move in (1, 2, 249, 250, 251, each.moves - 1):
            assert boundary_at(each, move) == boundary_at(from_start, move)


def test_a_stream_without_take_ups_is_the_plan_as_it_is() -> None:
    plan = plan_program(program_of(chords(120)), CONFIG)
    band = Band.of(CONFIG)
    assert not band.active  # this machine has no backlash
    fast = TakeUps(CONFIG).compensate(plan.segments, [(5, 3)])
    one_by_one = Stream(plan.segments)
    for index in range(len(plan.segments)):
        one_by_one.add_base(index)
    assert fast.stream == one_by_one
    assert fast.pauses == [(5, 3)] and fast.band_start == fast.band_end == band
