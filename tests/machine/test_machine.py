"""The machine layer on the real emulator: the agreement check, one program at a time, the stop rule,
jobs with pauses, and the hooks that homing and probing use (reports, waiting for an event)."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from quadstep.config import MachineConfig, parse_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine, MachineError, Target, open_machine
from quadstep.protocol import HoldDone, Segment, State
from quadstep.kernel.motion import AxisMove

CONFIG: MachineConfig = parse_config({
    "tick_hz": 50000,
    "axes": [
        {"name": "X", "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 100},
        {"name": "Y", "steps_per_mm": 80, "max_speed": 50, "max_accel": 500, "travel_min": 0, "travel_max": 100},
        {"name": "Z", "steps_per_mm": 400, "max_speed": 10, "max_accel": 200, "travel_min": -20, "travel_max": 0},
    ],
}, "test machine")


def plan_of(tmp_path: Path, text: str, machine: Machine):  # noqa: ANN201
    job = tmp_path / "job.gcode"
    job.write_text(text)
    return load_job(job, machine.config, machine.sync()).plan


def machine_on(start_emulator, free: bool):  # noqa: ANN001, ANN201
    emu = start_emulator(free=free, axes=3)
    machine = Machine(Link.open(emu.url), CONFIG)
    yield machine
    machine.close()


@pytest.fixture
def paced(start_emulator) -> Machine:  # noqa: ANN001
    """Real time, so that a stop lands mid-move."""
    yield from machine_on(start_emulator, free=False)


@pytest.fixture
def free(start_emulator) -> Machine:  # noqa: ANN001
    yield from machine_on(start_emulator, free=True)


def test_the_firmware_must_agree_with_the_configuration(start_emulator) -> None:  # noqa: ANN001
    emu = start_emulator(free=True, axes=2, tick_hz=40000)
    with Link.open(emu.url) as link:
        with pytest.raises(MachineError, match=r"^m.toml: tick_hz = 50000, but the firmware ticks at 40000 Hz"):
            Machine(link, CONFIG, source="m.toml")
        fewer = CONFIG.model_copy(update={"tick_hz": 40000})
        with pytest.raises(MachineError, match=r"^m.toml: 3 axes configured, the firmware drives 2$"):
            Machine(link, fewer, source="m.toml")
        generic = Machine(link, None)  # a generic configuration from what the firmware says
        assert not generic.config_given and generic.axis_count == 2 and generic.config.tick_hz == 40000


def test_it_knows_where_it_stands_at_connection(free: Machine) -> None:
    free.set_position({0: 800, 2: -400})
    again = Machine(free.link, CONFIG)
    assert again.position == (800, 0, -400)
    assert again.position_mm == (10.0, 0.0, -1.0)


def test_a_job_ends_exactly_where_it_was_planned(free: Machine, tmp_path: Path) -> None:
    plan = plan_of(tmp_path, "G1 X10 Y5 F1200\nG1 Z-1\n", free)
    end = free.run_job(plan).wait(30)
    assert end is not None and end.ended_by == "done"
    assert free.position == plan.end == (800, 400, -400) == tuple(free.link.status().position)
    assert not free.busy


def test_one_program_at_a_time(paced: Machine, tmp_path: Path) -> None:
    job = paced.run_job(plan_of(tmp_path, "G1 X20 F600\n", paced))
    with pytest.raises(MachineError, match="a program is running already"):
        paced.move(plan_of(tmp_path, "G1 Y5 F600\n", paced).segments)
    with pytest.raises(MachineError, match="cannot set the position: a program is running"):
        paced.set_position({0: 0})
    assert paced.program is job
    paced.hold()
    assert not paced.busy


def test_the_users_stop_is_a_hold_to_rest_at_the_exact_position(paced: Machine, tmp_path: Path) -> None:
    plan = plan_of(tmp_path, "G1 X30 F600\n", paced)  # 3 s
    job = paced.run_job(plan)
    threading.Event().wait(0.5)
    end = paced.hold()
    assert end is not None and end.ended_by == "stop" and end.held and end.hold_tick is not None
    status = paced.link.status()
    assert status.state == State.IDLE and status.queue_fill == 0
    assert paced.position == end.position == tuple(status.position) and 0 < end.position[0] < 2400
    assert job.wait(1) == end
    assert paced.hold() is None  # nothing runs any more


def test_the_emergency_stop_is_immediate_and_keeps_the_position_exact(paced: Machine, tmp_path: Path) -> None:
    motion = paced.move(plan_of(tmp_path, "G1 X30 F600\n", paced).segments)
    threading.Event().wait(0.5)
    status = paced.emergency_stop()
    end = motion.wait(5)
    assert end is not None and end.ended_by == "reset" and not end.held
    assert paced.position == tuple(status.position) == end.position and 0 < end.position[0] < 2400


def test_a_job_waits_at_every_pause_even_the_first_and_the_last(free: Machine, tmp_path: Path) -> None:
    plan = plan_of(tmp_path, "M0\nG1 X5 F1200\nM0\nG1 X10\nM0\n", free)
    job = free.run_job(plan)
    seen = []
    for line in (1, 3, 5):
        for _ in range(500):
            if job.paused_at is not None:
                break
            threading.Event().wait(0.01)
        seen.append((job.paused_at, free.link.status().position[0]))
        assert job.resume()
    end = job.wait(10)
    assert end is not None and end.ended_by == "done"
    assert seen == [(1, 0), (3, 400), (5, 800)]
    assert not job.resume()  # not paused any more


def test_a_job_halted_at_a_pause_ends_there(free: Machine, tmp_path: Path) -> None:
    job = free.run_job(plan_of(tmp_path, "G1 X5 F1200\nM0\nG1 X10\n", free))
    for _ in range(500):
        if job.paused_at == 2:
            break
        threading.Event().wait(0.01)
    end = job.halt("stop")
    assert end.ended_by == "stop" and end.position == (400, 0, 0) == free.position
    assert job.progress.line == 3  # the line it would have gone on with


def test_raw_segments_and_waiting_for_an_event(free: Machine) -> None:
    motion = free.send_segments([Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=4096, vn=0, r=0),))])
    end = motion.wait(10)
    assert end is not None and end.ended_by == "done" and free.position == (100, 0, 0)
    seen = free.report_count(HoldDone)
    reports = []
    unregister = free.on_report(reports.append)
    # It ends moving, so the free-running board waits for more instead of finishing at once: the
    # hold always finds it running, however late this thread gets to it.
    motion = free.send_segments([Segment(n=1000, axes=(AxisMove(axis=1, direction=1, v0=0, vn=2048, r=0),))])
    assert free.hold() is not None
    done = free.wait_report(HoldDone, seen, timeout=5)
    unregister()
    assert isinstance(done, HoldDone) and done in reports
    assert free.report_count(HoldDone) == seen + 1


def test_open_machine_starts_and_stops_its_emulator(emulator_binary: Path) -> None:  # noqa: ANN001
    target = Target(emulator=True, emulator_options={"free": True, "binary": emulator_binary})
    machine = open_machine(target, CONFIG)
    emulator = machine.emulator
    assert emulator is not None and emulator.running and machine.identity.axis_count == 3
    machine.close()
    assert not emulator.running
