"""GRBL's override bytes through the front door on the real emulator: the feed override (0x90–0x94)
re-plans the running batch on the way and the job still ends on its exact steps; rapid (0x95–0x97)
and spindle (0x99–0x9D) overrides are in the status report's Ov: and in what is planned next (a
slower rapid, a scaled S), the targets untouched."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import JobRun, Machine
from quadstep.machine.speed_overrides import SpeedOverrides
from quadstep.planner.plan import plan_program

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
CONFIG_S = CONFIG.model_copy(
    update={"spindle": CONFIG.spindle.model_copy(update={"s_max": 10000.0})}
)


@pytest.fixture
def door(start_emulator) -> Iterator[tuple[Machine, GrblClient]]:
    """The emulator ticking in real time, so that a batch is still running when a byte arrives."""
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, free=False)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                yield machine, grbl


def ov(report: str) -> str | None:
    return report_fields(report).get("Ov")


def test_the_feed_override_replans_the_running_batch_and_it_ends_exactly(
    door: tuple[Machine, GrblClient],
) -> None:
    machine, grbl = door
    # moves of 2 mm: boundaries ahead where the rest is planned again
    lines = ["G1 X2 F600", *(f"X{x}" for x in range(4, 41, 2))]
    assert grbl.stream_counting(lines) == ["ok"] * len(lines)
    grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
    job = machine.program
    assert isinstance(job, JobRun)
    planned = job.plan
    for byte in (0x91, 0x91, 0x91, 0x93, 0x94, 0x91, 0x91):  # +10 ×3, +1, −1, +10 ×2: 150 %
        grbl.realtime(byte)
    report = grbl.wait_status(lambda r: ov(r) is not None and ov(r) != "100,100,100")
    assert ov(report) == "150,100,100"
    running = grbl.wait_status(lambda r: r.startswith("<Run") and job.feed_override == 150)
    assert report_fields(running)["FS"].startswith("900,")
    done = grbl.wait_status(lambda r: r.startswith("<Idle"))
    assert job.plan is not planned  # the rest was planned again at 150 %, moving
    assert mpos(done) == (40.0, 0.0, 0.0)
    assert tuple(machine.link.status().position[:3]) == CONFIG.to_steps((40.0, 0.0, 0.0))
    grbl.realtime(0x90)
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,100,100"
    for _ in range(25):
        grbl.realtime(0x92)  # −10 % each, held at 10 %
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "10,100,100"


def test_rapid_and_spindle_overrides_are_reported_and_planned_next(
    door: tuple[Machine, GrblClient],
) -> None:
    machine, grbl = door
    grbl.realtime(0x97)  # rapids at 25 %
    for byte in (0x9A, 0x9A, 0x9D):  # spindle +10 +10 −1: 119 %
        grbl.realtime(byte)
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,25,119"
    assert machine.speed_overrides.rapid == 25 and machine.speed_overrides.spindle == 119
    assert grbl.command("G0 X5 Y2")[1] == "ok"
    assert mpos(grbl.wait_status(lambda r: r.startswith("<Idle"))) == (5.0, 2.0, 0.0)
    grbl.realtime(0x18)  # a soft reset: every override back to 100 %
    grbl.wait_banner()
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,100,100"


def test_a_rapid_at_25_percent_takes_longer_and_ends_on_the_same_steps() -> None:
    program = parse_gcode("G0 X100 Y20\nG1 X90 F600\nG0 X0 Y0\n", CONFIG.axis_names)
    overrides = SpeedOverrides()
    full = plan_program(overrides.apply(program, CONFIG, (0, 0, 0)), CONFIG)
    overrides.set_rapid(25)
    slow = plan_program(overrides.apply(program, CONFIG, (0, 0, 0)), CONFIG)
    assert slow.end == full.end == (0, 0, 0)
    assert slow.move_ends.tolist() != [] and len(slow.move_ends) == len(full.move_ends)
    ticks = sum(int(n) for n in full.segments.n), sum(int(n) for n in slow.segments.n)
    assert ticks[1] > 3 * ticks[0]  # the feed move is the same; the rapids four times as long


def test_the_spindle_override_scales_the_s_sent() -> None:
    program = parse_gcode("M3 S5000\nG1 X10 F600\nM5\n", CONFIG_S.axis_names)
    overrides = SpeedOverrides()
    overrides.set_spindle(150)
    plan = plan_program(overrides.apply(program, CONFIG_S, (0, 0, 0)), CONFIG_S)
    powers = [message.power for _, _, message in plan.outputs]
    assert powers[0] == CONFIG_S.spindle.power(7500) and powers[-1] == 0
    with pytest.raises(ValueError, match="outside 10–200"):
        overrides.set_spindle(201)
    with pytest.raises(ValueError, match="25, 50, 100"):
        overrides.set_rapid(75)


def test_coolant_toggles_at_rest(door: tuple[Machine, GrblClient]) -> None:
    _, grbl = door
    grbl.realtime(0xA0)  # flood on
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M5 M8 T0 F0 S0]"]
    assert "|A:F" in grbl.wait_status(lambda r: ov(r) is not None)
    grbl.realtime(0xA1)  # mist on
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M5 M7 M8 T0 F0 S0]"]
    assert grbl.command("M3 S100")[1] == "ok"  # a line keeps them
    grbl.wait_status(lambda r: r.startswith("<Idle"))
    report = grbl.wait_status(lambda r: ov(r) is not None)
    assert report.endswith("|A:SFM>")
    grbl.realtime(0xA0)
    grbl.realtime(0xA1)
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M3 M9 T0 F0 S100]"]
