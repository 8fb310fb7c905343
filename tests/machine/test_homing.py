"""Homing through the machine layer, on the emulator with the example router's simulated machine: machine zero
lands on the same motor step whatever the power-up position, a switch closed at power-up is pulled off first, a
missing switch is a clear error, homing_required refuses jobs until homed, and a hard limit loses the position.
Every move inside the travel stays clear of the switches: a park at machine zero (G53 Z0, G28) after a job to the
far corner does not stop on a hard limit, as it does on GRBL, whose machine zero is at its switches."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config, parse_config
from quadstep.machine import Machine, MachineError, Target, open_machine
from quadstep.machine.homing import HomingError, home
from quadstep.planner.plan import plan_program
from quadstep.planner.program import LinearMove, Program

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
MACHINE = (REPO / "examples" / "router-uno-machine.toml").read_text()


def machine_file(tmp_path: Path, starts: tuple[int, int, int] | None = None) -> Path:
    text = MACHINE
    if starts is not None:
        for old, new in zip(("start = 40000", "start = 30000", "start = -8000"), starts):
            text = text.replace(old, f"start = {new}")
    path = tmp_path / f"machine-{abs(hash(text))}.toml"
    path.write_text(text)
    return path


def open_sim(start_emulator, path: Path, config=CONFIG) -> Machine:
    emu = start_emulator(free=True, tick_hz=config.tick_hz, axes=3, queue=16, extra_args=["--machine", str(path)])
    return open_machine(Target(emulator=True), config, emulator=emu)


@pytest.mark.parametrize("starts", [(40000, 30000, -8000), (1234, 70001, -20111)])
def test_homing_sets_zero_on_the_same_motor_step_from_anywhere(start_emulator, tmp_path: Path,
                                                              starts: tuple[int, int, int]) -> None:
    path = machine_file(tmp_path, starts)
    emu = start_emulator(free=True, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(path)])
    machine = open_machine(Target(emulator=True), CONFIG, emulator=emu)
    progress: list[str] = []
    results = home(machine, on_progress=progress.append)
    assert [r.name for r in results] == ["Z", "X", "Y"]  # Z first
    assert machine.homed and not machine.position_lost
    position = machine.position
    machine.close()
    axes = emu.stop()["machine"]["axes"]
    # The switches close at motor 0 (X, Y: carriage <= 0 after half the dead band; Z: >= 0): the switch's
    # point is the first step past that, whatever the start, and machine zero is the pull-off (1 mm, 400 steps)
    # off it, inside the travel.
    zero = [axes[i]["motor"] - position[i] for i in range(3)]
    assert zero == [-6 + 400, -4 + 400, 2 - 400]  # floor(0 - backlash/2) for X and Y, ceil(0 + backlash/2) for Z
    assert position == (0, 0, 0)  # pulled off to the travel's end, clear of every switch
    assert any("seeking" in line for line in progress)


def test_a_switch_closed_at_power_up_is_pulled_off_first(start_emulator, tmp_path: Path) -> None:
    machine = open_sim(start_emulator, machine_file(tmp_path, (-3, 30000, 2)))
    messages: list[str] = []
    home(machine, ["X"], messages.append)
    assert "X: switch closed already, pulling off" in messages
    assert machine.position[0] == 0
    assert not machine.homed  # only X of three
    machine.close()


def test_a_missing_switch_is_an_error_naming_the_axis(start_emulator, tmp_path: Path) -> None:
    path = tmp_path / "no-switch.toml"
    path.write_text("[[axis]]\nstart = 4000\n[[axis]]\n[[axis]]\n")  # nothing wired
    machine = open_sim(start_emulator, path)
    with pytest.raises(HomingError, match="axis X: no switch within 450.0 mm"):
        home(machine, ["X"])
    machine.close()


def test_homing_required_refuses_jobs_until_homed_and_a_hard_limit_loses_the_position(start_emulator,
                                                                                     tmp_path: Path) -> None:
    data = CONFIG.model_dump()
    data["homing_required"] = True
    config = parse_config(data)
    machine = open_sim(start_emulator, machine_file(tmp_path), config)

    def job(x: float):
        program = Program(items=[LinearMove(line=1, target=(x, 1, -1), feed=20)], lines=1)
        return plan_program(program, config, machine.position)

    with pytest.raises(MachineError, match="home the machine first"):
        machine.run_job(job(5))
    home(machine)
    machine.run_job(job(5)).wait(30)
    assert machine.position[0] == 2000
    # Past the travel on purpose, as a job would not: the switch at X = -1 mm is a hard limit now.
    unbounded = config.model_copy(update={"axes": tuple(a.model_copy(update={"travel_min": -50}) for a in config.axes)})
    program = Program(items=[LinearMove(line=1, target=(-5, 1, -1), feed=20)], lines=1)
    machine.run_job(plan_program(program, unbounded, machine.position)).wait(30)
    assert machine.position_lost and not machine.homed
    with pytest.raises(MachineError, match="home the machine first"):
        machine.run_job(job(5))
    machine.close()


def test_the_whole_travel_is_clear_of_the_switches(start_emulator, tmp_path: Path) -> None:
    machine = open_sim(start_emulator, machine_file(tmp_path))
    home(machine)
    corners = [(300.0, 200.0, -60.0), (0.0, 0.0, 0.0), (300.0, 0.0, 0.0), (0.0, 200.0, -60.0), (0.0, 0.0, 0.0)]
    items = [LinearMove(line=n, target=corner, feed=50) for n, corner in enumerate(corners, 1)]
    plan = plan_program(Program(items=items, lines=len(items)), CONFIG, machine.position)
    end = machine.run_job(plan).wait(60)
    assert end is not None and end.ended_by == "done", end
    assert machine.position == (0, 0, 0) and machine.homed and not machine.position_lost
    machine.close()


def test_an_inverted_axis_homes_to_its_travel_end_clear_of_its_switch(start_emulator, tmp_path: Path) -> None:
    """X inverted: its machine minimum is the motor's maximum, where its switch is (closed at motor 0 and above), on
    the axis's one limit pin as on the Uno."""
    data = CONFIG.model_dump()
    data["axes"][0]["invert"] = True
    config = parse_config(data)
    text = MACHINE.replace("start = 40000", "start = -40000", 1).replace(
        "hard_min = -400\nhard_max = 120800\n[axis.limit_min]", "hard_min = -120800\nhard_max = 400\n[axis.limit_max]", 1)
    path = tmp_path / "inverted.toml"
    path.write_text(text)
    emu = start_emulator(free=True, tick_hz=config.tick_hz, axes=3, queue=16,
                         extra_args=["--machine", str(path), "--limit-pins", "1"])
    machine = open_machine(Target(emulator=True), config, emulator=emu)
    home(machine, ["X"])
    assert machine.position[0] == 0  # machine X 0, the travel's end
    items = [LinearMove(line=1, target=(300.0, 1.0, -1.0), feed=50), LinearMove(line=2, target=(0.0, 1.0, -1.0), feed=50)]
    start = machine.position
    plan = plan_program(Program(items=items, lines=2), config, start)
    end = machine.run_job(plan).wait(60)
    assert end is not None and end.ended_by == "done", end
    assert machine.position[0] == 0 and not machine.position_lost
    machine.close()
    motor = emu.stop()["machine"]["axes"][0]["motor"]
    assert -400 - 6 <= motor <= -400 + 6  # the pull-off (400 steps) off the switch's point, within the dead band
