"""The G-code reader: every supported word, modal state, arcs, and exact error messages."""

from __future__ import annotations

import math
from typing import Any

import pytest

from quadstep.config import parse_config
from quadstep.gcode import GcodeError, parse_gcode, split_words
from quadstep.planner.plan import plan_program
from quadstep.planner.program import Dwell, LinearMove, Pause

XYZ = ("X", "Y", "Z")


def moves(text: str, axes: tuple[str, ...] = XYZ, **options: Any) -> list[LinearMove]:
    program = parse_gcode(text, axes, **options)
    return [item for item in program.items if isinstance(item, LinearMove)]


def targets(text: str, **options: Any) -> list[tuple[float, ...]]:
    return [tuple(round(x, 9) for x in m.target) for m in moves(text, **options)]


def error(text: str, axes: tuple[str, ...] = XYZ, **options: Any) -> str:
    with pytest.raises(GcodeError) as caught:
        parse_gcode(text, axes, **options)
    return str(caught.value)


# --- words and comments -------------------------------------------------------------


def test_words_keep_their_text_value_and_column() -> None:
    words = split_words("g1x-1.5 Y.25 (comment) F+600 ; rest", 1)
    assert [(w.letter, w.number, w.value, w.column) for w in words] == [
        ("G", "1", 1.0, 1),
        ("X", "-1.5", -1.5, 3),
        ("Y", ".25", 0.25, 9),
        ("F", "+600", 600.0, 24),
    ]


def test_comments_of_both_styles_and_percent_lines_are_ignored() -> None:
    text = "%\n(setup) G1 X1 F60 (mid) Y2 ; tail X9\n;G1 X5\n%\n"
    assert targets(text) == [(1.0, 2.0, 0.0)]


def test_line_numbers_are_accepted_first_only() -> None:
    assert targets("N10 G1 X1 F60\nN20 X2") == [(1.0, 0, 0), (2.0, 0, 0)]
    assert error("G1 N10 X1 F60") == "line 1, column 4: 'N10' (line number) must be the first word"


# --- motion, modal state, units, distance modes ---------------------------------------


def test_g0_is_rapid_and_g1_uses_the_modal_feed_in_units_per_minute() -> None:
    result = moves("G0 X5 F1200\nG1 Y5\nX0 F600\nG0 Y0")
    assert [(m.feed, m.target) for m in result] == [
        (None, (5.0, 0.0, 0.0)),
        (20.0, (5.0, 5.0, 0.0)),
        (10.0, (0.0, 5.0, 0.0)),
        (None, (0.0, 0.0, 0.0)),
    ]


def test_motion_mode_is_modal_across_lines() -> None:
    assert targets("G1 F60 X1\nY1\nZ-1") == [(1, 0, 0), (1, 1, 0), (1, 1, -1)]


def test_inches_convert_coordinates_and_feed() -> None:
    result = moves("G20 G1 X1 F10\nG21 X1")
    assert result[0].target == (25.4, 0.0, 0.0)
    assert result[0].feed == pytest.approx(25.4 * 10 / 60)
    assert result[1].target == (1.0, 0.0, 0.0)
    assert result[1].feed == pytest.approx(25.4 * 10 / 60)  # the feed stays what it was set to


def test_relative_and_absolute_distance() -> None:
    assert targets("G91 G1 X1 Y2 F60\nX1\nG90 X0") == [(1, 2, 0), (2, 2, 0), (0, 2, 0)]


def test_start_position_is_where_relative_moves_begin() -> None:
    assert targets("G91 G1 X1 F60", start=(10.0, 20.0, -1.0)) == [(11.0, 20.0, -1.0)]
    assert targets("G90 G1 X1 F60", start=(10.0, 20.0, -1.0)) == [(1.0, 20.0, -1.0)]


def test_g92_sets_the_program_origin_at_the_current_position() -> None:
    text = "G1 X10 Y10 F60\nG92 X0 Y0\nG1 X5\nG92 X100\nG1 X101\nG91 X1"
    assert targets(text) == [(10, 10, 0), (15, 10, 0), (16, 10, 0), (17, 10, 0)]


def test_g92_in_inches_and_with_a_move_on_the_next_line() -> None:
    assert targets("G20 G92 X1\nG1 X2 F1") == [(25.4, 0, 0)]


def test_dwell_pause_and_end() -> None:
    program = parse_gcode("G1 X1 F60\nG4 P0.5\nM0\nG1 X2\nM30\nG1 X3", XYZ)
    assert program.items == [
        LinearMove(1, (1.0, 0.0, 0.0), 1.0),
        Dwell(2, 0.5),
        Pause(3),
        LinearMove(4, (2.0, 0.0, 0.0), 1.0),
    ]
    assert program.end_line == 5
    assert parse_gcode("M2\nG1 X9 F1", XYZ).items == []


def test_mode_only_words_are_accepted() -> None:
    assert targets("G17 G21 G40 G49 G54 G80 G90 G94\nG1 X1 F60") == [(1, 0, 0)]


def test_inverse_time_g93_gives_each_feed_move_1_over_f_minutes() -> None:
    line, *chords = moves("G93 G1 X10 F6\nG2 X20 Y0 I5 F3")
    assert line.feed == pytest.approx(1.0)  # 10 mm in 10 s
    assert len({m.feed for m in chords}) == 1  # one speed along the arc
    path = sum(math.dist(a.target, b.target) for a, b in zip([line, *chords], chords))
    assert path / chords[0].feed == pytest.approx(20.0)  # the semicircle in 1/3 minute
    (rotary,) = moves("G93 G1 X1 A90 F60", axes=("X", "A"))
    assert rotary.feed == pytest.approx(math.hypot(1, 90))  # every axis's path, as GRBL measures it
    assert moves("G93 G1 X1 F60\nG94 G1 X2 F120")[1].feed == 2.0  # units per minute again


def test_an_inverse_time_job_takes_the_minutes_its_f_words_give() -> None:
    config = parse_config({"tick_hz": 32000, "axes": [
        {"name": n, "steps_per_mm": 400, "max_speed": 40, "max_accel": 2000, "travel_min": -100, "travel_max": 100}
        for n in XYZ]})
    program = parse_gcode("G93 G1 X10 F6\nG1 X20 Y10 F4\nG2 X30 Y0 I0 J-10 F2", XYZ)
    plan = plan_program(program, config, (0, 0, 0))
    assert plan.duration_s == pytest.approx(10 + 15 + 30, abs=0.05)  # the ramps: a few ms


def test_inverse_time_wants_f_on_every_feed_line_and_g94_after_it_a_new_f() -> None:
    assert error("G93 G1 X1 F60\nX2") == (
        "line 2, column 1: G1 in inverse time (G93) needs F on its own line "
        "(GRBL error 22: feed rate has not yet been set or is undefined)"
    )
    assert error("G1 X1 F60\nG93 G0 X5\nG94 G1 X2") == (
        "line 3, column 5: G1 needs a feed rate: no F on this line or before "
        "(GRBL error 22: feed rate has not yet been set or is undefined)"
    )
    assert targets("G93 G1 X1 F60\nG0 X3") == [(1, 0, 0), (3, 0, 0)]  # a rapid needs no F


def test_a_move_and_a_pause_on_one_line_move_first() -> None:
    items = parse_gcode("G1 X1 F60 M0", XYZ).items
    assert items == [LinearMove(1, (1.0, 0.0, 0.0), 1.0), Pause(1)]


def test_four_axes() -> None:
    assert targets("G1 X1 Y2 Z3 A4 F60", axes=("X", "Y", "Z", "A")) == [(1, 2, 3, 4)]


# --- arcs ---------------------------------------------------------------------------


def arc_points(text: str, tolerance: float = 0.001, axes: tuple[str, ...] = XYZ) -> list[tuple[float, ...]]:
    return [m.target for m in moves(text, axes, arc_tolerance=tolerance)]


def check_on_circle(
    points: list[tuple[float, ...]], center: tuple[float, float], radius: float, i: int, j: int
) -> None:
    for p in points:
        assert math.dist((p[i], p[j]), center) == pytest.approx(radius, abs=1e-9)


@pytest.mark.parametrize(
    ("plane", "first", "second", "offsets"),
    [("G17", 0, 1, ("I", "J")), ("G18", 2, 0, ("K", "I")), ("G19", 1, 2, ("J", "K"))],
)
def test_quarter_arcs_in_every_plane_and_both_directions(
    plane: str, first: int, second: int, offsets: tuple[str, str]
) -> None:
    names = ("X", "Y", "Z")
    a, b = names[first], names[second]
    # from (10, 0) around (0, 0) to (0, 10) in the plane's own coordinates
    start = f"G1 {a}10 {b}0 F600\n"
    ccw = arc_points(start + f"{plane} G3 {a}0 {b}10 {offsets[0]}-10 {offsets[1]}0")[1:]
    cw = arc_points(start + f"{plane} G2 {a}0 {b}10 {offsets[0]}-10 {offsets[1]}0")[1:]
    check_on_circle(ccw, (0.0, 0.0), 10.0, first, second)
    check_on_circle(cw, (0.0, 0.0), 10.0, first, second)
    # counter-clockwise goes the short way (90°) through the first quadrant,
    # clockwise the long way (270°) through the other three
    assert all(p[first] >= -1e-9 and p[second] >= -1e-9 for p in ccw)
    assert any(p[first] < -5 for p in cw) and any(p[second] < -5 for p in cw)
    assert len(cw) == pytest.approx(3 * len(ccw), abs=2)
    assert ccw[-1][first] == 0.0 and ccw[-1][second] == 10.0


def test_chords_stay_within_the_tolerance() -> None:
    radius, tolerance = 25.0, 0.002
    points = arc_points("G1 X25 Y0 F600\nG3 X-25 Y0 I-25 J0", tolerance)
    for p, q in zip(points, points[1:]):
        middle = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
        assert radius - math.hypot(*middle) <= tolerance + 1e-12
    # no more chords than needed: one fewer would break the tolerance
    angle = 2 * math.acos(1 - tolerance / radius)
    assert len(points) - 1 == math.ceil(math.pi / angle)


def test_full_circle_with_offsets_returns_to_its_start() -> None:
    points = arc_points("G1 X10 Y0 F600\nG2 I-10 J0", 0.01)
    assert points[-1] == (10.0, 0.0, 0.0)
    check_on_circle(points[1:], (0.0, 0.0), 10.0, 0, 1)
    assert len(points) > 20


def test_radius_form_short_and_long_way() -> None:
    short = arc_points("G1 X0 Y0 F600\nG2 X10 Y0 R10")[1:]
    long = arc_points("G1 X0 Y0 F600\nG2 X10 Y0 R-10")[1:]
    # the short clockwise arc from (0,0) to (10,0) bulges up with its center below
    check_on_circle(short, (5.0, -math.sqrt(75)), 10.0, 0, 1)
    assert max(p[1] for p in short) == pytest.approx(10 - math.sqrt(75), abs=1e-3)
    check_on_circle(long, (5.0, math.sqrt(75)), 10.0, 0, 1)
    assert max(p[1] for p in long) == pytest.approx(10 + math.sqrt(75), abs=1e-3)


def test_helical_arc_moves_the_third_axis_evenly() -> None:
    points = arc_points("G1 X10 Y0 Z0 F600\nG3 X-10 Y0 Z-4 I-10 J0", 0.01)[1:]
    zs = [p[2] for p in points]
    steps = [b - a for a, b in zip([0.0] + zs, zs)]
    assert zs[-1] == -4.0
    assert max(steps) == pytest.approx(min(steps))


def test_arc_offsets_are_relative_even_in_absolute_mode() -> None:
    points = arc_points("G1 X20 Y10 F600\nG90 G3 X10 Y20 I-10 J0")[1:]
    check_on_circle(points, (10.0, 10.0), 10.0, 0, 1)


def test_arc_in_inches() -> None:
    points = arc_points("G20 G1 X1 Y0 F60\nG3 X0 Y1 I-1 J0")[1:]
    check_on_circle(points, (0.0, 0.0), 25.4, 0, 1)


# --- skipping machine functions -------------------------------------------------------


def test_skip_unsupported_lists_every_skipped_word() -> None:
    text = "M3 S12000\nG1 X1 F60 M8\nT2 M6\nM5 M9"
    program = parse_gcode(text, XYZ, skip_unsupported=True)
    assert program.skipped == [(1, "M3"), (1, "S12000"), (2, "M8"), (3, "T2"), (3, "M6"), (4, "M5"), (4, "M9")]
    assert [m.target for m in program.items if isinstance(m, LinearMove)] == [(1.0, 0.0, 0.0)]


def test_skip_unsupported_does_not_skip_unknown_words() -> None:
    assert error("G43 H1", skip_unsupported=True) == "line 1, column 1: 'G43' is not supported"


# --- malformed input: each with its exact message --------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G1 X1 F60\nG1 X2 Y", "line 2, column 7: 'Y' has no number after it"),
        ("G1 X1 # F60", "line 1, column 7: '#': parameters (variables) are not supported"),
        ("G1 X1 F60 ! X2", "line 1, column 11: unexpected character '!'"),
        ("o100 sub", "line 1, column 1: 'o100': O-word flow control (subroutines, loops, conditions) is not "
                     "supported"),
        ("o<probe> sub", "line 1, column 1: 'o<probe>': O-word flow control (subroutines, loops, conditions) "
                         "is not supported"),
        ("G1 X1 E0.5 F60", "line 1, column 7: 'E0.5' drives an extruder: this is a 3D-printer file (extruder "
                           "and heater codes); quadstep runs CNC G-code"),
        ("M104 S200", "line 1, column 1: 'M104' is a 3D printer's code: this is a 3D-printer file (extruder "
                      "and heater codes); quadstep runs CNC G-code"),
        ("M3 M5", "line 1, column 4: 'M5' and 'M3' contradict each other"),
        ("M8 M9", "line 1, column 4: 'M9' and 'M8' contradict each other"),
        ("M6", "line 1, column 1: M6 needs a tool: no T on this line or before"),
        ("T1.5", "line 1, column 1: 'T1.5': a tool is a whole number"),
        ("S-1", "line 1, column 1: 'S-1': the spindle speed must be at least 0"),
        ("G64 P0", "line 1, column 5: 'P0': the path tolerance must be greater than 0 and at most 10 mm"),
        ("G1 X1 F60 Q2", "line 1, column 11: 'Q2' is only used with G64"),
        ("G1 X1 (open comment", "line 1, column 7: comment '(' is not closed on this line"),
        ("G1 X1 X2 F60", "line 1, column 7: 'X2' repeats X (first at column 4)"),
        ("G0 G1 X1", "line 1, column 4: 'G1' and 'G0' are both in the motion group"),
        ("G20 G21", "line 1, column 5: 'G21' and 'G20' are both in the units group"),
        ("G4 P1 G92 X0", "line 1, column 7: 'G92' and 'G4' are both in the non-modal group"),
        ("M0 M30", "line 1, column 4: 'M30' and 'M0' are both program stops"),
        ("G38.2 Z-10", "line 1, column 1: G38.2 needs a feed rate: no F on this line or before "
                       "(GRBL error 22: feed rate has not yet been set or is undefined)"),
        ("G38.3 F60", "line 1, column 1: G38.3 needs an axis word: where to probe toward"),
        ("G38.2 Z0 F60", "line 1, column 1: G38.2: the target is where the machine already is"),
        ("G53 G38.2 Z-5 F60", "line 1, column 1: G53 does not apply to probing"),
        ("G43 H1", "line 1, column 1: 'G43' is not supported"),
        ("G1 X1 F60 B2", "line 1, column 11: 'B2' is not supported"),
        ("M1.5", "line 1, column 1: 'M1.5' is not supported"),
        ("G1 A5 F60", "line 1, column 4: 'A5': axis A is not on this machine (axes X, Y, Z)"),
        ("G80 X10", "line 1, column 1: 'G80': axis words without a motion mode (G0, G1, G2 or G3)"),
        ("G1 X10", "line 1, column 1: G1 needs a feed rate: no F on this line or before "
                   "(GRBL error 22: feed rate has not yet been set or is undefined)"),
        ("G0 X1\nY2 G2 I1 J0", "line 2, column 4: G2 needs a feed rate: no F on this line or before "
                               "(GRBL error 22: feed rate has not yet been set or is undefined)"),
        ("G1 X1 F0", "line 1, column 7: 'F0': the feed rate must be greater than 0"),
        ("G1 X1 F-5", "line 1, column 7: 'F-5': the feed rate must be greater than 0"),
        ("G4", "line 1, column 1: G4 needs P (seconds)"),
        ("G4 P-1", "line 1, column 4: 'P-1': the dwell must be at least 0 seconds"),
        ("G4 P1 X1", "line 1, column 7: 'X1': G4 takes no axis words"),
        ("G4 P3600.001", "line 1, column 4: 'P3600.001': a dwell may last at most 3600 s (an "
                         "hour; M0 waits for the operator as long as it takes)"),
        ("G1 X" + "9" * 400 + " F60", "line 1, column 4: 'X999999999999…': a number of 400 digits "
                                      "is too large to be represented"),
        ("G1 X1 F" + "9" * 309, "line 1, column 7: 'F999999999999…': a number of 309 digits is too "
                                "large to be represented"),
        ("G1 F60\nG2 X0 Y0 I-100000000000000", "line 2, column 1: G2 of radius 1e+14 mm would be "
                                                "more than 100000 chords at arc_tolerance "
                                                "0.002 mm"),
        ("G1 X1 F60 P2", "line 1, column 11: 'P2' is only used with G4, G10 and G64"),
        ("G92", "line 1, column 1: G92 needs at least one axis word"),
        ("G1 X1 F60 I5", "line 1, column 11: 'I5' is only used with G2/G3"),
        ("G1 F60\nG2 X10 Y0", "line 2, column 1: G2 needs I/J offsets or R"),
        ("G1 F60\nG18 G3 X10 Z0", "line 2, column 5: G3 needs K/I offsets or R"),
        ("G1 F60\nG2 X10 Y0 K5", "line 2, column 11: 'K5' is not an offset in the G17 plane (I, J)"),
        ("G1 F60\nG19 G2 Y10 Z0 I5", "line 2, column 15: 'I5' is not an offset in the G19 plane (J, K)"),
        ("G1 F60\nG2 X10 Y0 R5 I5", "line 2, column 11: G2 takes either R or I/J, not both"),
        ("G1 F60\nG2 X10 Y0 R4", "line 2, column 11: 'R4': radius 4.000 mm is less than half the distance "
                                 "to the end point (5.000 mm)"),
        ("G1 F60\nG2 X0 Y0 R4", "line 2, column 10: an R-form arc needs an end point different from its start"),
        ("G1 F60\nG2 X10 Y0 I6 J0", "line 2, column 1: G2 end point is not on the arc: radius 6.000 mm at "
                                    "the start, 4.000 mm at the end"),
        ("G1 F60\nG18 G2 X1 K1", "line 2, column 5: G18 arcs need axes Z and X on this machine"),
    ],
)
def test_malformed_input_is_refused_with_an_exact_message(text: str, message: str) -> None:
    axes = ("X", "Y") if "G18 G2" in text else XYZ
    assert error(text, axes) == message


def test_errors_carry_line_and_column() -> None:
    with pytest.raises(GcodeError) as caught:
        parse_gcode("G1 X1 F60\n\n  G1 Q7", XYZ)
    assert (caught.value.line, caught.value.column) == (3, 6)


def test_a_space_may_stand_between_a_letter_and_its_number() -> None:
    spaced = parse_gcode("G 1 X 10 y -5.5 F 600\nz 20", XYZ)
    plain = parse_gcode("G1 X10 Y-5.5 F600\nZ20", XYZ)
    assert spaced.items == plain.items
    assert split_words("X 10", 1)[0].text == "X10"
