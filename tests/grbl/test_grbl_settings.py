"""`$N=value` through the GRBL front door: written into a copy of the example router's configuration
file (comments kept, the old file as .bak), checked whole first (a bad value: GRBL's error, a
message naming the setting and the limit, nothing written), and used for the lines that follow, on
the real emulator. Also `--m6 pause`: a tool change holds until `~`."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving

from quadstep.config import load_config
from quadstep.grbl.session import SessionOptions
from quadstep.link import Link
from quadstep.machine import Machine

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "router-uno.toml"


def serve(start_emulator, options: SessionOptions) -> Iterator[tuple[Machine, GrblClient]]:
    config = load_config(options.config_path or EXAMPLE)
    emu = start_emulator(axes=3, tick_hz=config.tick_hz, free=True)
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        with serving(machine, options=options) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                yield machine, grbl


@pytest.fixture
def config_file(tmp_path: Path) -> Path:
    path = tmp_path / "quadstep.toml"
    shutil.copy(EXAMPLE, path)
    return path


@pytest.fixture
def door(start_emulator, config_file: Path) -> Iterator[tuple[Machine, GrblClient]]:
    yield from serve(start_emulator, SessionOptions(config_path=config_file))


def idle(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def test_settings_are_written_to_the_file_and_used_for_the_next_lines(
    door: tuple[Machine, GrblClient], config_file: Path
) -> None:
    machine, grbl = door
    assert grbl.command("$110=1200") == ([], "ok")  # X max rate, mm/min
    assert grbl.command("$130=100") == ([], "ok")  # X travel
    assert grbl.command("$132=50") == ([], "ok")  # Z travel: its top (machine zero) stays
    said, answer = grbl.command("$101=800")  # Y steps/mm: its 40 mm/s too fast then
    assert answer == "error:3" and "must be at most 30 mm/s" in said[0]
    assert grbl.command("$111=1200") == ([], "ok")
    assert grbl.command("$101=800") == ([], "ok")
    written = load_config(config_file)
    assert written.axes[0].max_speed == 20 and written.axes[0].travel_max == 100
    assert (written.axes[2].travel_min, written.axes[2].travel_max) == (-50, 0)
    assert written.axes[1].steps_per_mm == 800
    text = config_file.read_text()
    assert "# A typical small 3-axis CNC router" in text  # comments kept
    kept = load_config(config_file.with_name("quadstep.toml.bak"))  # before the last write
    assert kept.axes[1].steps_per_mm == 400 and kept.axes[1].max_speed == 20
    shown, answer = grbl.command("$$")
    assert answer == "ok" and {"$110=1200", "$130=100", "$132=50", "$101=800"} <= set(shown)
    assert grbl.command("G0 X150")[1] == "error:15"  # beyond the new travel
    assert grbl.command("G0 X100 Y10")[1] == "ok"
    assert mpos(grbl.wait_status(idle)) == (100.0, 10.0, 0.0)
    assert tuple(machine.link.status().position[:3]) == (40000, 8000, 0)  # 800 steps/mm on Y


def test_bad_and_fixed_settings_are_refused_and_nothing_is_written(
    door: tuple[Machine, GrblClient], config_file: Path
) -> None:
    _, grbl = door
    before = config_file.read_text()
    said, answer = grbl.command("$100=0")
    assert answer == "error:3" and said[0].startswith("[MSG:$100=0: ")
    assert "steps_per_mm" in said[0] and "greater than 0" in said[0]
    said, answer = grbl.command("$110=6000")  # 100 mm/s: over 3/4 step per tick at 400 steps/mm
    assert answer == "error:3" and "max_speed" in said[0] and "60" in said[0]
    assert grbl.command("$100=x")[1] == "error:2"
    assert grbl.command("$120=-5")[1] == "error:4"
    said, answer = grbl.command("$21=2")
    assert answer == "error:3" and "0 (off) or 1 (on)" in said[0]
    assert grbl.command("$0=10") == ([], "ok")  # a fixed setting written with its value
    said, answer = grbl.command("$0=5")
    assert answer == "error:3" and said == ["[MSG:$0 is fixed at 10 in quadstep]"]
    assert grbl.command("$99=1")[1] == "error:3"
    assert config_file.read_text() == before
    assert not config_file.with_name("quadstep.toml.bak").exists()


def test_without_a_configuration_file_writes_need_config(start_emulator) -> None:
    for _, grbl in serve(start_emulator, SessionOptions()):
        said, answer = grbl.command("$110=1200")
        assert answer == "error:3" and "--config FILE" in said[0]


def test_m6_pause_holds_until_cycle_start(start_emulator) -> None:
    for _, grbl in serve(start_emulator, SessionOptions(tool_change="pause")):
        assert grbl.stream_counting(["G0 X5", "T2 M6", "G0 X10"]) == ["ok"] * 3
        held = grbl.wait_status(lambda r: r.startswith("<Hold:0"))
        assert mpos(held) == (5.0, 0.0, 0.0)
        grbl.realtime(ord("~"))
        assert mpos(grbl.wait_status(idle)) == (10.0, 0.0, 0.0)


def test_the_homing_direction_mask_is_grbls_invert_mask(
    door: tuple[Machine, GrblClient], config_file: Path
) -> None:
    _, grbl = door
    assert "$23=3" in grbl.command("$$")[0]  # X and Y home toward min, Z toward max
    assert grbl.command("$23=1") == ([], "ok")
    assert [a.homing.end for a in load_config(config_file).axes if a.homing] == [
        "min",
        "max",
        "max",
    ]
    assert grbl.command("$24=120") == ([], "ok")  # the locate speed, mm/min
    assert {a.homing.locate for a in load_config(config_file).axes if a.homing} == {2.0}
