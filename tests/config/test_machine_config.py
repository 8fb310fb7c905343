"""Machine configuration: the example loads, and every bad value is named with its range."""

from __future__ import annotations

import copy
import re
import tomllib
from pathlib import Path
from typing import Any

import pytest

from quadstep.config import ConfigError, default_config, load_config, parse_config

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "router-uno.toml"

GOOD: dict[str, Any] = {
    "tick_hz": 50000,
    "axes": [
        {"name": "X", "steps_per_mm": 80, "max_speed": 200, "max_accel": 1000, "travel_min": 0, "travel_max": 300},
        {"name": "Y", "steps_per_mm": 80, "max_speed": 200, "max_accel": 1000, "travel_min": 0, "travel_max": 300},
    ],
}


def bad(change: dict[str, Any], axis: int | None = None) -> str:
    data = copy.deepcopy(GOOD)
    (data["axes"][axis] if axis is not None else data).update(change)
    with pytest.raises(ConfigError) as caught:
        parse_config(data, "m.toml")
    return str(caught.value)


def test_the_example_router_config_loads() -> None:
    config = load_config(EXAMPLE)
    assert config.axis_names == ("X", "Y", "Z")
    # the rate the Uno firmware is built with, which it reports at identify
    uno_tick = re.search(r"^AVR_UNO_TICK_HZ \?= (\d+)$", (REPO / "firmware/avr/avr.mk").read_text(), re.M)
    assert uno_tick is not None and config.tick_hz == int(uno_tick.group(1))
    for axis in config.axes:
        # under 3/4 step per tick at the firmware's tick rate
        assert axis.max_speed * axis.steps_per_mm <= 0.75 * config.tick_hz


def test_defaults_for_cornering_and_arcs() -> None:
    config = parse_config(GOOD)
    assert config.junction_deviation == 0.01
    assert config.arc_tolerance == 0.002


@pytest.mark.parametrize(
    ("change", "axis", "message"),
    [
        ({"tick_hz": 0}, None, "m.toml: tick_hz = 0: must be at least 1000"),
        ({"junction_deviation": -1}, None, "m.toml: junction_deviation = -1: must be greater than 0"),
        ({"arc_tolerance": 0}, None, "m.toml: arc_tolerance = 0: must be greater than 0"),
        ({"steps_per_mm": 0}, 0, "m.toml: axes[0].steps_per_mm = 0: must be greater than 0"),
        ({"max_accel": -3}, 1, "m.toml: axes[1].max_accel = -3: must be greater than 0"),
        ({"name": "Q"}, 1, "m.toml: axes[1].name = 'Q': must be one of 'X', 'Y', 'Z' or 'A'"),
        ({"travel_max": -1}, 0, "m.toml: axes[0].travel_max = -1.0: must be greater than travel_min = 0.0"),
        ({"max_speed": 500}, 1, "m.toml: axes[1].max_speed = 500.0: must be at most 468.75 mm/s "
                                "(3/4 step per tick at tick_hz 50000 with 80 steps/mm)"),
        ({"laser": 1}, None, "m.toml: laser: unknown key"),
        ({"spindle": {"s_max": 0}}, None, "m.toml: spindle.s_max = 0: must be greater than 0"),
        ({"spindle": {"s_min": 2000}}, None, "m.toml: spindle.s_min = 2000: must be less than s_max = 1000"),
        ({"max_jerk": 1}, 0, "m.toml: axes[0].max_jerk = 1: must be at least 4.657e+04 mm/s³ (64 jerk quanta of a "
                             "cubic segment at tick_hz 50000 with 80 steps/mm, so that rounding it errs by under 1 %)"),
        ({"max_jerk": 1e9}, 0, "m.toml: axes[0].max_jerk = 1e+09: must be at most 2.38411e+07 mm/s³ (a cubic "
                               "segment's 16-bit jerk at tick_hz 50000 with 80 steps/mm)"),
        ({"max_jerk": -1}, 0, "m.toml: axes[0].max_jerk = -1: must be greater than 0"),
    ],
)
def test_bad_values_name_key_value_and_range(change: dict[str, Any], axis: int | None, message: str) -> None:
    assert bad(change, axis) == message


SPEED_FLOOR = ("1/4096 step per tick, a segment's finest speed, at tick_hz 50000 with 80 "
               "steps/mm")
ACCEL_FLOOR = ("2^-24 step per tick², a hold's gentlest deceleration, at tick_hz 50000 with 80 "
               "steps/mm")


@pytest.mark.parametrize(
    ("change", "axis", "message"),
    [  # scales that would silently move nothing, or plan without end
        ({"max_jerk": 5e-324}, 0, "axes[0].max_jerk = 4.94066e-324: must be at least 4.657e+04 "
                                  "mm/s³ (64 jerk quanta of a cubic segment at tick_hz 50000 with "
                                  "80 steps/mm, so that rounding it errs by under 1 %)"),
        ({"steps_per_mm": 5e-324}, 0, "axes[0].steps_per_mm = 4.94066e-324: must be at least 1 "
                                      "(a 1 mm move makes at least one step)"),
        ({"steps_per_mm": 0.4}, 0, "axes[0].steps_per_mm = 0.4: must be at least 1 (a 1 mm move "
                                   "makes at least one step)"),
        ({"travel_max": 0.01}, 1, "axes[1].travel_max = 0.01: must be at least one step "
                                  "(0.0125 mm) beyond travel_min = 0"),
        ({"max_speed": 1e-300}, 0, f"axes[0].max_speed = 1e-300: must be at least 0.1526 mm/s "
                                   f"({SPEED_FLOOR})"),
        ({"max_accel": 5e-324}, 1, f"axes[1].max_accel = 4.94066e-324: must be at least 1.863 "
                                   f"mm/s² ({ACCEL_FLOOR})"),
        ({"homing": {"seek": 1e-9}}, 0, f"axes[0].homing.seek = 1e-09: must be at least 0.1526 "
                                        f"mm/s ({SPEED_FLOOR})"),
        ({"backlash": {"mm": 0.1, "accel": 1}}, 0, f"axes[0].backlash.accel = 1: must be at least "
                                                   f"1.863 mm/s² ({ACCEL_FLOOR})"),
    ],
)
def test_scales_below_what_the_machine_can_do_are_refused(change: dict[str, Any], axis: int,
                                                          message: str) -> None:
    assert bad(change, axis) == f"m.toml: {message}"


def test_the_floors_themselves_are_allowed() -> None:
    """One speed quantum and one deceleration quantum are the least values: allowed, exactly."""
    data = copy.deepcopy(GOOD)
    data["axes"][0].update(steps_per_mm=1, max_speed=50000 / 4096, max_accel=50000**2 / 2**24,
                           travel_max=1)
    assert parse_config(data).axes[0].max_speed == 50000 / 4096


def test_missing_and_duplicate_axes() -> None:
    data = copy.deepcopy(GOOD)
    del data["axes"][0]["travel_min"]
    with pytest.raises(ConfigError, match=r"^m\.toml: axes\[0\]\.travel_min: missing$"):
        parse_config(data, "m.toml")
    data = copy.deepcopy(GOOD)
    data["axes"][1]["name"] = "X"
    with pytest.raises(ConfigError, match=r"^m\.toml: axes: names must be unique, got \['X', 'X'\]$"):
        parse_config(data, "m.toml")


def test_every_problem_is_reported_at_once() -> None:
    data = copy.deepcopy(GOOD)
    data["tick_hz"] = 10
    data["axes"][0]["steps_per_mm"] = -1
    with pytest.raises(ConfigError) as caught:
        parse_config(data, "m.toml")
    assert str(caught.value).splitlines() == [
        "m.toml: tick_hz = 10: must be at least 1000",
        "m.toml: axes[0].steps_per_mm = -1: must be greater than 0",
    ]


def test_unreadable_and_malformed_files(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read"):
        load_config(tmp_path / "absent.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("tick_hz = = 5\n")
    with pytest.raises(ConfigError, match=r"broken\.toml: not valid TOML"):
        load_config(broken)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"tick_hz = \xff\n")
    with pytest.raises(ConfigError, match=r"^.*binary\.toml: not a text file \(invalid start byte at byte 10\)$"):
        load_config(binary)


def test_steps_are_rounded_once_from_absolute_millimetres() -> None:
    axis = parse_config(GOOD).axes[0]
    assert axis.to_steps(0.00625) == 1  # 0.5 step rounds up
    assert axis.to_steps(-0.00625) == 0
    assert axis.to_steps(12.3456) == 988
    inverted = axis.model_copy(update={"invert": True})
    assert inverted.to_steps(12.3456) == -988
    assert inverted.to_mm(-988) == pytest.approx(12.35)


def test_axis_names_are_the_protocols() -> None:
    """The letters a configuration accepts are the wire's axes 0 … 3 (pydantic needs them as a Literal)."""
    from typing import get_args

    from quadstep.config import AxisName
    from quadstep.protocol import AXIS_NAMES

    assert get_args(AxisName) == AXIS_NAMES


@pytest.mark.parametrize("tick_hz", [1000, 32000, 50000, 1_000_000])
def test_the_configuration_for_an_unknown_board_loads_at_every_tick_rate(tick_hz: int) -> None:
    """Its acceleration is at least what a hold can brake (746 mm/s² at 1 MHz and 80 steps/mm)."""
    axis = default_config(tick_hz, 4).axes[0]
    assert axis.max_accel >= 500 and axis.max_accel * 80 >= tick_hz**2 / 2**24


def test_every_commented_setting_of_the_example_can_be_uncommented() -> None:
    """A user who uncomments a setting of examples/router-uno.toml (and the table it sits in) gets a
    valid configuration with it, never a key read into the wrong table."""
    text = (REPO / "examples" / "router-uno.toml").read_text()
    uncommented = re.sub(r"(?m)^# (\[\[?[a-z_.]+\]\]?|[a-z_]+ = .*)$", r"\1", text)
    assert uncommented.count("\n") == text.count("\n") and uncommented != text
    config = parse_config(tomllib.loads(uncommented))
    assert config.homing_required and config.safe_z == -5


def test_a_homing_switch_inside_the_travel_is_refused_with_hard_limits() -> None:
    """A move to the travel's end would close the switch there and stop on a hard limit; by default the switch is
    pull_off beyond the end, where homing puts it."""
    inside = {"homing": {"end": "min", "switch_at": 0}}
    assert bad(inside, axis=0) == (
        "m.toml: axes[0].homing.switch_at = 0: inside X's travel 0 … 300 mm, where a move to it closes the switch "
        "and stops on ALARM HARD_LIMIT (hard_limits = true); leave switch_at out (it is then pull_off beyond the "
        "travel's end) or end the travel short of it"
    )
    data = copy.deepcopy(GOOD)
    data["axes"][0]["homing"] = {"end": "min", "pull_off": 2}
    assert parse_config(data).axes[0].switch_at == -2  # the default: pull_off beyond travel_min
    data["axes"][1]["homing"] = {"end": "max", "switch_at": 300.5}
    assert parse_config(data).axes[1].switch_at == 300.5  # beyond the travel: as given
    data["inputs"] = {"hard_limits": False}
    data["axes"][0]["homing"] = inside["homing"]
    assert parse_config(data).axes[0].switch_at == 0  # no hard limit to stop on
