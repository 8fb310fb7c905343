"""Work coordinates in G-code, as GRBL and LinuxCNC have them: G54–G59, G10 L2/L20, G53, G92 and
G92.1–G92.3, G28/G30 with G28.1/G30.1, M2/M30; and travel errors that name the line's own value."""

from __future__ import annotations

import pytest

from quadstep.config import parse_config
from quadstep.coordinates import WorkCoordinates
from quadstep.gcode import GcodeError, parse_gcode
from quadstep.planner.plan import plan_program
from quadstep.planner.program import JobError, LinearMove

XYZ = ("X", "Y", "Z")


def program(text: str, coordinates: WorkCoordinates | None = None, start: tuple[float, ...] = (0.0, 0.0, 0.0)):  # noqa: ANN201
    return parse_gcode(text, XYZ, start, coordinates=coordinates)


def targets(text: str, coordinates: WorkCoordinates | None = None, **options: object) -> list[tuple[float, ...]]:
    items = program(text, coordinates, **options).items  # type: ignore[arg-type]
    return [tuple(round(x, 9) for x in m.target) for m in items if isinstance(m, LinearMove)]


def offsets(**systems: dict[str, float]) -> WorkCoordinates:
    coords = WorkCoordinates()
    for name, values in systems.items():
        for axis, mm in values.items():
            coords.set_offset(int(name[1:]) - 53, axis, mm)
    return coords


def error(text: str, coordinates: WorkCoordinates | None = None) -> str:
    with pytest.raises(GcodeError) as caught:
        program(text, coordinates)
    return str(caught.value)


def test_moves_are_in_the_active_systems_work_coordinates() -> None:
    coords = offsets(G54={"X": 10, "Y": -5}, G55={"X": 100})
    assert targets("G1 X1 Y1 F60\nG55 X1\nY0\nG54 X0", coords) == [(11, -4, 0), (101, -4, 0), (101, 0, 0), (10, 0, 0)]
    assert targets("G91 G1 X1 F60", coords) == [(1, 0, 0)]  # relative moves do not see offsets


def test_g10_l2_sets_a_systems_offset_and_l20_makes_the_current_position_read_a_value() -> None:
    text = "G10 L2 P2 X20 Z-3\nG55 G0 X0 Z0\nG10 L20 P0 X5\nG0 X5\nG10 L20 P1 Y0\nG54 G0 Y1"
    assert targets(text, start=(0.0, 7.0, 0.0)) == [(20, 7, -3), (20, 7, -3), (20, 8, -3)]
    result = program(text, start=(0.0, 7.0, 0.0)).coordinates
    assert result is not None
    assert result.offsets[1] == {"X": 15.0, "Z": -3.0} and result.offsets[0] == {"Y": 7.0}
    assert result.name == "G54"


def test_g10_values_are_in_program_units_and_absolute_in_g91() -> None:
    coords = program("G20 G91 G10 L2 P1 X1\nG10 L2 P1 X1").coordinates
    assert coords is not None and coords.offsets[0] == {"X": 25.4}


def test_g53_moves_in_machine_coordinates_for_its_line_only() -> None:
    coords = offsets(G54={"X": 10, "Z": -2})
    assert targets("G53 G0 X0 Z0\nG1 X0 F60\nG53 G1 X3", coords) == [(0, 0, 0), (10, 0, 0), (3, 0, 0)]
    assert error("G91 G53 G0 X0") == "line 1, column 5: G53 moves in machine coordinates only with absolute distance (G90)"
    assert error("G1 F60\nG53 G2 X1 Y1 I1") == "line 2, column 1: G53 moves in machine coordinates only with G0 or G1"


def test_g92_sits_on_top_of_the_system_and_can_be_suspended_restored_and_cleared() -> None:
    coords = offsets(G54={"X": 10})
    text = "G0 X5\nG92 X0\nG1 X1 F60\nG92.2\nX1\nG92.3\nX1\nG92.1\nX1"
    assert targets(text, coords) == [(15, 0, 0), (16, 0, 0), (11, 0, 0), (16, 0, 0), (11, 0, 0)]
    result = program(text, coords).coordinates
    assert result is not None and result.g92 == {} and not result.g92_applied
    kept = program("G92 X2\nG92.2", coords).coordinates
    assert kept is not None and kept.g92 == {"X": -12.0} and not kept.g92_applied  # 0 − 10 − 2, for G92.3


def test_g10_l20_counts_the_g92_offset_in() -> None:
    coords = program("G92 X3\nG10 L20 P1 X0", start=(5.0, 0.0, 0.0)).coordinates
    assert coords is not None and coords.g92 == {"X": 2.0}  # X read 3 at machine 5
    assert coords.offsets[0] == {"X": 3.0}  # 5 − 2 − 0: X reads 0 here, with G92 on top
    assert coords.to_work(XYZ, (5.0, 0.0, 0.0))[0] == 0.0


def test_g28_and_g30_go_through_the_point_given_to_the_stored_position() -> None:
    text = "G0 X7 Y8 Z-1\nG28.1\nG0 X0 Y0 Z0\nG30.1\nG0 X1 Y2 Z-3\nG28\nG0 X1 Y2 Z-3\nG91 G28 Z1\nG90 G30 X4"
    assert targets(text) == [
        (7, 8, -1), (0, 0, 0), (1, 2, -3),
        (7, 8, -1),  # G28: straight to the stored position, every axis
        (1, 2, -3), (1, 2, -2), (1, 2, -1),  # G91 G28 Z1: up 1 mm, then Z alone to its stored -1
        (4, 2, -1), (0, 2, -1),  # G30 X4: through X4, then X alone to its stored 0
    ]
    stored = program(text).coordinates
    assert stored is not None and stored.g28 == {"X": 7.0, "Y": 8.0, "Z": -1.0} and stored.g30 == {"X": 0.0, "Y": 0.0, "Z": 0.0}


def test_program_end_returns_to_g54_and_suspends_g92() -> None:
    coords = program("G55 G92 X1\nM30").coordinates
    assert coords is not None and coords.name == "G54" and not coords.g92_applied and coords.g92 == {"X": -1.0}


def test_the_coordinates_given_are_not_changed() -> None:
    coords = offsets(G54={"X": 10})
    program("G10 L2 P1 X99\nG56", coords)
    assert coords.offsets[0] == {"X": 10.0} and coords.name == "G54"


def test_g43_1_offsets_z_by_the_tools_length_until_g49_and_moves_nothing_itself() -> None:
    coords = offsets(G54={"Z": -10})
    text = "G0 Z5\nG43.1 Z-2.5\nG0 Z5\nX1\nG91 G0 Z1\nG90 G49\nG0 Z5\nG20 G43.1 Z1\nG0 Z0"
    assert targets(text, coords) == [(0, 0, -5), (0, 0, -7.5), (1, 0, -7.5), (1, 0, -6.5), (1, 0, -5), (1, 0, 15.4)]
    result = program(text, coords).coordinates
    assert result is not None and result.tlo == 25.4 and result.offset("Z") == pytest.approx(15.4)
    assert result.to_work(XYZ, (0.0, 0.0, 15.4)) == pytest.approx((0.0, 0.0, 0.0))


def test_g10_l20_and_g92_count_the_tool_length_in_as_grbl_does() -> None:
    coords = program("G43.1 Z2\nG10 L20 P1 Z0", start=(0.0, 0.0, -20.0)).coordinates
    assert coords is not None and coords.offsets[0] == {"Z": -22.0}  # Z reads 0 here with the tool
    assert coords.to_work(XYZ, (0.0, 0.0, -20.0))[2] == 0.0
    coords = program("G43.1 Z2\nG92 Z1", start=(0.0, 0.0, -20.0)).coordinates
    assert coords is not None and coords.g92 == {"Z": -23.0}
    assert coords.to_work(XYZ, (0.0, 0.0, -20.0))[2] == 1.0


def test_m1_is_an_optional_stop_that_nothing_stops_at() -> None:
    parsed = program("G0 X1\nM1\nG0 X2")
    assert [m.target[0] for m in parsed.items if isinstance(m, LinearMove)] == [1, 2]
    assert parsed.end_line is None and not any(type(item).__name__ == "Pause" for item in parsed.items)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G10 L1 P1 X0", "line 1, column 5: 'L1' is not supported: G10 L2 and G10 L20 set work offsets"),
        ("G10 P1 X0", "line 1, column 1: G10 without L is not supported: G10 L2 and G10 L20 set work offsets"),
        ("G10 L2 X0", "line 1, column 1: G10 L2 needs P0 … P6 (0: the active system, 1 … 6: G54 … G59)"),
        ("G10 L20 P7 X0", "line 1, column 9: G10 L20 needs P0 … P6 (0: the active system, 1 … 6: G54 … G59)"),
        ("G10 L2 P1 R5 X0", "line 1, column 11: 'R5': rotated coordinate systems are not supported"),
        ("G10 L2 P1", "line 1, column 1: G10 needs at least one axis word"),
        ("G28.1 X1", "line 1, column 7: 'X1': G28.1 takes no axis words"),
        ("G92.1 X0", "line 1, column 7: 'X0': G92.1 takes no axis words"),
        ("G54 G55", "line 1, column 5: 'G55' and 'G54' are both in the coordinate system group"),
        ("G10 L2 P1 X0 G92 X1", "line 1, column 14: 'G92' and 'G10' are both in the non-modal group"),
        ("G1 X1 F60 L2", "line 1, column 11: 'L2' is only used with G10"),
        ("G54.1 P1", "line 1, column 1: 'G54.1' is not supported"),
        ("G43.1", "line 1, column 1: G43.1 takes one axis word, Z: the tool's length"),
        ("G43.1 X1 Z1", "line 1, column 7: G43.1 takes one axis word, Z: the tool's length"),
        ("G1 G43.1 Z1 F60", "line 1, column 1: 'G1' and G43.1 both want the line's axis words"),
        ("G43.1 Z1 G49", "line 1, column 10: 'G49' and 'G43.1' are both in the tool length offset group"),
    ],
)
def test_malformed_coordinate_words_are_refused_with_an_exact_message(text: str, message: str) -> None:
    assert error(text) == message


MACHINE = parse_config({"tick_hz": 50000, "axes": [
    {"name": n, "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 100}
    for n in XYZ]})


def test_a_move_outside_the_travel_is_named_by_its_own_work_value() -> None:
    coords = offsets(G55={"Y": 50})
    with pytest.raises(JobError) as caught:
        plan_program(program("G55 G1 X10 Y60 F600", coords), MACHINE, (0, 0, 0))
    assert str(caught.value) == "line 1: Y 60.000 mm in G55 (machine 110.000 mm) is outside the travel 0.000 … 100.000 mm"
    with pytest.raises(JobError) as caught:
        plan_program(program("G53 G0 Y101", coords), MACHINE, (0, 0, 0))
    assert str(caught.value) == "line 1: Y 101.000 mm is outside the travel 0.000 … 100.000 mm"


def test_soft_limits_stay_in_machine_coordinates_whatever_the_offset() -> None:
    coords = offsets(G54={"X": -50})  # work X 120 is machine 70: inside
    plan = plan_program(program("G1 X120 F600", coords), MACHINE, (0, 0, 0))
    assert plan.end == (5600, 0, 0)
