"""A job started at a line: the state the lines before it leave, the approach from where the
machine stands, and the rest exactly as the whole job has it (planner/approach.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from modal_job import JOB

from quadstep.config import ConfigError, MachineConfig, load_config, parse_config
from quadstep.gcode import parse_gcode
from quadstep.job import read_program
from quadstep.planner.approach import Approach, approach_to, describe, item_at_line, program_from
from quadstep.planner.moves import build_moves
from quadstep.planner.plan import plan_program
from quadstep.planner.program import (Dwell, Item, JobError, LinearMove, OutputState, Program,
                                      SetOutputs)

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
INCH = 25.4
# Inches, relative segments, G55 set by G10, the spindle on, off and on again, and a tool change,
# all before line 14.
G55 = (INCH, INCH, -0.2 * INCH)  # G55's origin, machine mm
AT = (100.0, 150.0, -30.0)  # where the machine stands, machine mm
ON_AT_14 = OutputState(spindle=3, speed=9000.0, flood=True)  # M3, M5, then M3 S9000 M8
F10 = 10 * INCH / 60  # mm/s


def program(text: str = JOB, config: MachineConfig = CONFIG) -> Program:
    return parse_gcode(text, config.axis_names, (0.0, 0.0, 0.0), config.arc_tolerance)


def configured(top: str = "", spindle: str = "") -> MachineConfig:
    """The router with `top` keys at the top of its file and a [spindle] table of `spindle`."""
    text = f"{top}\n{ROUTER.read_text()}\n[spindle]\n{spindle}\n"
    return parse_config(tomllib.loads(text), "m.toml")


def machine_of(work: tuple[float, float, float]) -> tuple[float, ...]:
    return tuple(w * INCH + o for w, o in zip(work, G55))


def target(item: Item) -> tuple[float, ...]:
    assert isinstance(item, LinearMove)
    return item.target


def kinds(approach: Approach) -> list[type]:
    return [type(i) for i in approach.items]


def test_the_state_before_the_line_is_rebuilt() -> None:
    whole = program()
    first = item_at_line(whole, 14)
    approach = approach_to(whole, first, CONFIG, AT)
    assert approach.outputs == ON_AT_14
    assert approach.tool is not None and (approach.tool.tool, approach.tool.line) == (2, 4)
    assert approach.system == "G55" and approach.offset == pytest.approx(G55)
    assert approach.feed == pytest.approx(F10)  # F10 in/min, line 13's
    # Line 13 leaves the tool at work X1.0 Y0.75 Z-0.04 (in inches, from relative moves).
    assert approach.begin == pytest.approx(machine_of((1.0, 0.75, -0.04)))
    rest = program_from(whole, first, CONFIG, AT)
    assert rest.items[len(approach.items):] == whole.items[first:]
    line14 = rest.items[len(approach.items)]
    assert line14.line == 14
    assert target(line14) == pytest.approx(machine_of((0.5, 1.0, -0.04)))  # G91 Y0.25
    assert rest.coordinates == whole.coordinates  # what the job leaves: G55 as line 2 set it


def test_the_approach_lifts_travels_restores_the_outputs_and_plunges() -> None:
    config = configured("safe_z = -5", "s_max = 24000\nspin_up_s = 2.5")
    whole = program(config=config)
    approach = approach_to(whole, item_at_line(whole, 14), config, AT)
    lift, over, outputs, wait, down = approach.items
    begin = approach.begin
    assert isinstance(lift, LinearMove) and lift.feed is None and lift.system == "G53"
    assert lift.target == (100.0, 150.0, -5.0)
    assert isinstance(over, LinearMove) and over.feed is None
    assert over.target == pytest.approx((begin[0], begin[1], -5.0))
    assert outputs == SetOutputs(14, ON_AT_14)
    assert wait == Dwell(14, 2.5)
    assert isinstance(down, LinearMove) and down.feed == pytest.approx(F10)
    assert down.target == begin
    assert approach.moves == ("lift", "over", "down")
    rest = program_from(whole, item_at_line(whole, 14), config, AT)
    assert rest.items[:5] == [lift, over, outputs, wait, down]  # the program's first items
    plan = plan_program(rest, config, config.to_steps(AT))
    assert plan.end == plan_program(whole, config).end
    assert plan.duration_s > 2.5  # the spin-up's dwell is in it
    assert describe(approach, config) == (
        "starting at line 14: Z up to -5.000 mm (machine), X 25.400 Y 19.050 mm (G55) at rapid, "
        "spindle M3 S9000 on, flood coolant on, 2.5 s spin-up, Z down to -1.016 mm (G55) at "
        "F254 mm/min; tool T2 (line 4) must be in the spindle")


def test_without_safe_z_the_lift_goes_to_the_top_of_z() -> None:
    whole = program()
    approach = approach_to(whole, item_at_line(whole, 14), CONFIG, AT)
    assert kinds(approach) == [LinearMove, LinearMove, SetOutputs, LinearMove]  # no spin-up
    assert approach.lift == 0.0 and target(approach.items[0]) == (100.0, 150.0, 0.0)


def test_every_target_of_the_rest_is_the_whole_jobs() -> None:
    whole = program()
    full_table = build_moves(whole, CONFIG, (0, 0, 0))
    full_plan = plan_program(whole, CONFIG, (0, 0, 0))
    start = CONFIG.to_steps(AT)
    for line in range(5, 17):
        first = item_at_line(whole, line)
        rest = program_from(whole, first, CONFIG, AT)
        moves_before = sum(isinstance(i, LinearMove) for i in whole.items[:first])
        approach = approach_to(whole, first, CONFIG, AT)
        table = build_moves(rest, CONFIG, start)
        assert table.target[len(approach.moves):] == full_table.target[moves_before:], line
        assert table.line[len(approach.moves)] >= line
        assert plan_program(rest, CONFIG, start).end == full_plan.end


def test_a_line_that_does_not_move_starts_at_the_next_that_does() -> None:
    whole = program()
    first = item_at_line(whole, 12)  # M3 S9000 M8: its outputs are the approach's
    approach = approach_to(whole, first, CONFIG, AT)
    assert approach.line == 12 and approach.outputs == ON_AT_14
    after = program_from(whole, first, CONFIG, AT).items[len(approach.items):]
    assert isinstance(after[0], LinearMove) and after[0].line == 13  # line 12's change is made
    assert approach.begin == pytest.approx(machine_of((1.0, 0.75, 0.1)))  # where line 11 left it
    assert item_at_line(whole, 3) == item_at_line(whole, 4)  # G55 alone has no item of its own


def test_a_start_inside_an_arc_goes_to_the_chord_it_stopped_on() -> None:
    whole = program()
    chords = [k for k, i in enumerate(whole.items) if isinstance(i, LinearMove) and i.line == 15]
    assert len(chords) > 10
    first = chords[len(chords) // 2]
    rest = program_from(whole, first, CONFIG, AT)
    approach = approach_to(whole, first, CONFIG, AT)
    assert approach.begin == target(whole.items[first - 1])
    assert rest.items[len(approach.items):] == whole.items[first:]
    assert approach.feed == pytest.approx(F10)  # the arc's own feed


def test_the_feed_there_is_the_last_one_set_when_the_line_is_a_rapid() -> None:
    whole = program()
    approach = approach_to(whole, item_at_line(whole, 16), CONFIG, AT)  # G0 after the arc at F10
    assert approach.feed == pytest.approx(F10)
    approach = approach_to(whole, item_at_line(whole, 6), CONFIG, (0.0, 0.0, -30.0))  # no F yet
    assert approach.feed == pytest.approx(20 * INCH / 60)  # the first one after it


def test_already_over_the_start_only_z_moves_and_a_high_z_stays() -> None:
    whole = program()
    first = item_at_line(whole, 14)
    begin = approach_to(whole, first, CONFIG, AT).begin
    approach = approach_to(whole, first, CONFIG, (begin[0], begin[1], begin[2] + 3.0))
    assert approach.moves == ("down",) and approach.lift is None
    approach = approach_to(whole, first, CONFIG, begin)
    assert approach.moves == () and kinds(approach) == [SetOutputs]
    assert describe(approach, CONFIG).startswith(
        "starting at line 14: spindle M3 S9000 on, flood coolant on")
    high = (5.0, 5.0, -2.0)  # above safe_z: no lift, it travels at its own height
    approach = approach_to(whole, first, configured("safe_z = -20"), high)
    assert approach.moves == ("over", "down") and target(approach.items[0])[2] == -2.0


def test_in_laser_mode_the_outputs_come_after_the_plunge() -> None:
    config = configured(spindle="s_max = 1000\nlaser = true\nspin_up_s = 3")
    whole = program("G21 G90\nM4 S500\nG0 X10 Y10 Z-2\nG1 X20 F600\nG1 Y20\nM5\nM30\n", config)
    approach = approach_to(whole, item_at_line(whole, 5), config, (0.0, 0.0, -30.0))
    assert kinds(approach) == [LinearMove, LinearMove, LinearMove, SetOutputs]  # no spin-up
    text = describe(approach, config)
    assert "Z down to -2.000 mm (G54) at F600 mm/min, laser M4 S500 on" in text


def test_a_machine_without_z_travels_straight_over() -> None:
    axes = [{"name": n, "steps_per_mm": 80, "max_speed": 100, "max_accel": 500, "travel_min": 0,
             "travel_max": 300} for n in "XY"]
    config = parse_config({"tick_hz": 32000, "axes": axes})
    whole = parse_gcode("G1 X10 Y10 F600\nG1 X20\nG1 Y20\n", ("X", "Y"))
    approach = approach_to(whole, item_at_line(whole, 3), config, (50.0, 50.0))
    assert approach.moves == ("over",) and target(approach.items[0]) == (20.0, 10.0)


@pytest.mark.parametrize(("line", "message"), [
    (0, "line 0: lines are counted from 1"),
    (18, "line 18 is past the end of the job (17 lines)"),
    (17, "line 17: nothing moves from here on (the last motion is at line 16)"),
])
def test_a_line_it_cannot_start_at_is_refused_naming_it(line: int, message: str) -> None:
    whole = program()
    with pytest.raises(JobError) as error:
        approach_to(whole, item_at_line(whole, line), CONFIG, AT)
    assert str(error.value) == message


def test_comments_after_the_last_motion_are_nothing_to_start_at() -> None:
    whole = program("G21 G90\nG1 X10 F600\n(done)\n\n")
    with pytest.raises(JobError) as error:
        item_at_line(whole, 3)
    assert str(error.value) == "line 3: nothing moves from here on (the last motion is at line 2)"


def test_a_line_after_a_probe_is_refused() -> None:
    whole = program("G21 G90\nG0 X10 Y10\nG38.2 Z-40 F100\nG10 L20 P1 Z0\nG0 Z5\nG1 X20 Z-1 F300\n")
    with pytest.raises(JobError) as error:
        approach_to(whole, item_at_line(whole, 6), CONFIG, AT)
    assert str(error.value) == ("line 6 comes after the probe at line 3 (G38.2): what follows "
                                "depends on where it stops; start at line 3 or before it")
    approach = approach_to(whole, item_at_line(whole, 3), CONFIG, AT)  # at the probe: it probes
    assert approach.begin == (10.0, 10.0, 0.0) and approach.feed == pytest.approx(100 / 60)


def test_safe_z_is_checked_against_the_travel() -> None:
    with pytest.raises(ConfigError) as error:
        configured("safe_z = 5")
    assert str(error.value) == "m.toml: safe_z = 5: must be within Z's travel -60 … 0 mm"
    assert configured("safe_z = -12.5").clearance_z == -12.5
    with pytest.raises(ConfigError) as error:
        configured(spindle="spin_up_s = -1")
    assert "spindle.spin_up_s = -1" in str(error.value)


def test_a_move_file_starts_at_its_move_in_machine_coordinates() -> None:
    moves = read_program(REPO / "examples" / "moves.yaml", CONFIG, (0, 0, 0))
    first = item_at_line(moves, 3, "move")
    approach = approach_to(moves, first, CONFIG, (0.0, 0.0, 0.0), label="move")
    assert describe(approach, CONFIG, "move") == (
        "starting at move 3: X 10.000 Y 10.000 mm (machine) at rapid, Z down to -1.000 mm "
        "(machine) at F1200 mm/min")
