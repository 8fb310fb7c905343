"""G38.2–G38.5 through the GRBL front door, on the emulator's simulated machine (a touch plate and a
block, no backlash): the [PRB:…] a sender reads is within one step of the simulated surface, `$#`
keeps it, a touch-off (G10 L20 after the probe) works from where the probe stopped, a G38.3 miss
answers `:0`, a G38.2 miss raises ALARM:5 and a probe touching already ALARM:4."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving

from quadstep.config import load_config
from quadstep.link import Link
from quadstep.machine import Machine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
STEPS = 400  # steps/mm on every axis of the example router
PLATE_Z = -16000.5  # motor steps: the plate's top, under X 50…100 mm, Y 50…100 mm
BLOCK_X = 60000  # the block's left side (X 150 mm), its top at Z -30 mm
SIM = f"""
seed = 1
[[axis]]
start = 0
[[axis]]
start = 0
[[axis]]
start = 0
[probe]
hysteresis = 1
[[probe.target]]
kind = "plate"
z = {PLATE_Z}
x_min = 20000
x_max = 40000
y_min = 20000
y_max = 40000
[[probe.target]]
kind = "block"
x_min = {BLOCK_X}
x_max = 80000
y_min = 20000
y_max = 40000
z = -12000
"""


@pytest.fixture
def grbl(start_emulator, tmp_path: Path) -> Iterator[GrblClient]:
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        free=True, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as client:
                client.wait_banner()
                yield client


def prb(line: str) -> tuple[tuple[float, ...], int]:
    """[PRB:x,y,z:1] → ((x, y, z), 1)."""
    body = line.removeprefix("[PRB:").removesuffix("]")
    position, found = body.rsplit(":", 1)
    return tuple(float(x) for x in position.split(",")), int(found)


def idle(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def test_a_z_touch_off_on_the_plate(grbl: GrblClient) -> None:
    assert grbl.command("G21 G90 G0 X75 Y75 Z-30")[1] == "ok"
    said, answer = grbl.command("G38.2 Z-50 F100")
    assert answer == "ok"
    position, found = prb(said[-1])
    assert found == 1 and position[:2] == (75.0, 75.0)
    assert abs(position[2] * STEPS - PLATE_Z) <= 1.0
    resting = grbl.wait_status(idle)
    rest = mpos(resting)[2]  # a little below the contact: it decelerated
    assert position[2] - 0.1 < rest <= position[2]
    assert report_fields(resting)["Pn"] == "P"  # the probe touches the plate
    # a sender's touch-off where it rests: the plate is 10 mm thick, then up to work Z 20
    assert grbl.command("G10 L20 P1 Z10")[1] == "ok"
    assert grbl.command("G0 Z20")[1] == "ok"
    report = grbl.wait_status(lambda r: idle(r) and "WCO" in r)
    assert "Pn" not in report_fields(report)  # lifted off it
    wco = tuple(float(x) for x in report_fields(report)["WCO"].split(","))
    assert wco[2] == pytest.approx(rest - 10, abs=1e-9)
    assert mpos(report)[2] == pytest.approx(rest + 10, abs=1e-9)
    offsets, answer = grbl.command("$#")
    assert answer == "ok" and said[-1] in offsets


def test_a_side_probe_on_the_block_and_a_g38_3_miss(grbl: GrblClient) -> None:
    assert grbl.command("G0 Z-35")[1] == "ok"
    assert grbl.command("G0 X140 Y75")[1] == "ok"
    said, answer = grbl.command("G38.2 X160 F200")
    position, found = prb(said[-1])
    assert answer == "ok" and found == 1
    assert abs(position[0] * STEPS - BLOCK_X) <= 1.0
    assert grbl.command("G0 X140")[1] == "ok"
    assert grbl.command("G0 Z-5 Y150")[1] == "ok"
    said, answer = grbl.command("G38.3 Z-20 F300")  # nothing under Y 150
    assert answer == "ok" and said[-1] == "[PRB:140.000,150.000,-20.000:0]"
    assert mpos(grbl.wait_status(idle)) == (140.0, 150.0, -20.0)


def test_a_g38_2_miss_alarms_and_a_probe_touching_already_too(grbl: GrblClient) -> None:
    assert grbl.command("G0 X75 Y150 Z-5")[1] == "ok"
    said, answer = grbl.command("G38.2 Z-10 F300")
    assert answer == "ok"
    assert said[-2:] == ["ALARM:5", "[PRB:0.000,0.000,0.000:0]"]
    assert report_fields(grbl.status())["state"] == "Alarm"
    assert grbl.command("G0 Y75")[1] == "error:9"
    assert grbl.command("$X")[1] == "ok"
    assert grbl.command("G0 Y75")[1] == "ok"
    said, answer = grbl.command("G38.2 Z-50 F100")
    assert answer == "ok" and prb(said[-1])[1] == 1
    said, answer = grbl.command("G38.2 Z-50 F100")  # it rests on the plate
    assert answer == "ok" and "ALARM:4" in said


def test_a_feed_hold_rests_a_probe_and_cycle_start_goes_on_with_it(
    start_emulator, tmp_path: Path
) -> None:
    """As GRBL: `!` during a G38.2 brings the machine to rest (Hold:0) for as long as it takes;
    `~` goes on toward the same target, and the probe touches the plate as it would have."""
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        free=False, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                assert grbl.command("G21 G90 G0 X75 Y75 Z-34")[1] == "ok"
                grbl.wait_status(idle)
                grbl.port.write(b"G38.2 Z-50 F120\n")  # 2 mm/s: the plate at Z-40 in 3 s
                grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[2] < -35)
                grbl.realtime(ord("!"))
                held = grbl.wait_status(lambda r: r.startswith("<Hold:0"))
                assert -40 < mpos(held)[2] < -35
                still = grbl.status()  # at rest, waiting
                assert still.startswith("<Hold:0") and mpos(still) == mpos(held)
                assert grbl.answers.empty()
                grbl.realtime(ord("~"))
                assert grbl.answer() == "ok"
                position, found = prb(grbl.drain_other()[-1])
                assert found == 1 and abs(position[2] * STEPS - PLATE_Z) <= 1.0
                assert grbl.command("G0 Z-30")[1] == "ok"  # lines go on from where it rests
                assert mpos(grbl.wait_status(idle)) == (75.0, 75.0, -30.0)


def test_a_reset_during_a_held_probe_ends_it(start_emulator, tmp_path: Path) -> None:
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        free=False, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                grbl.port.write(b"G38.3 Z-30 F120\n")  # 2 mm/s over the bare table: 15 s
                grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[2] < -0.5)
                grbl.realtime(ord("!"))
                rest = mpos(grbl.wait_status(lambda r: r.startswith("<Hold:0")))
                grbl.realtime(0x18)
                grbl.wait_banner()
                assert grbl.answers.empty()  # the probe's line is not answered after a reset
                assert grbl.command("$X")[1] == "ok"
                assert mpos(grbl.wait_status(idle)) == rest
                assert tuple(machine.link.status().position[:3]) == CONFIG.to_steps(rest)


@pytest.mark.realtime
def test_the_lines_before_a_probe_are_answered_before_it_waits(start_emulator, tmp_path: Path) -> None:
    """Answers to the lines a sender has in flight are written together once no more have come,
    but never held back behind a line that waits for the machine: a move and a probe sent at once,
    the move is answered while it runs, the probe once it has touched."""
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(sim)])
    with Link.open(emu.url) as link, serving(Machine(link, CONFIG)) as pty:
        with GrblClient(str(pty.path)) as grbl:
            grbl.wait_banner()
            assert grbl.command("G21 G90 G0 X75 Y75 Z-38")[1] == "ok"
            grbl.wait_status(idle)
            grbl.port.write(b"G1 X76 F60\nG38.2 Z-50 F100\n")  # a second's move, then the probe
            assert grbl.answer() == "ok"
            moving = report_fields(grbl.status())
            assert moving["state"] == "Run" and mpos(grbl.status())[0] < 76.0
            assert grbl.drain_other() == []  # no [PRB:…] yet
            assert grbl.answer() == "ok"
            position, found = prb(grbl.drain_other()[-1])
            assert found == 1 and position[:2] == (76.0, 75.0)
