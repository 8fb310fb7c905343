"""A tool change (T M6) in a job: a pause with the spindle off, where the operator jogs and sets Z's zero, and
the job goes on from there in the new offsets — on the emulator, through the machine layer."""

from __future__ import annotations

import time
from pathlib import Path

from quadstep.config import load_config
from quadstep.gcode import parse_gcode
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.machine.errors import MachineError
from quadstep.planner.plan import plan_program

import pytest

ROUTER = Path(__file__).resolve().parents[2] / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
JOB = "G21 G90 G54\nS1000 M3\nG0 X10 Y10\nG1 Z-5 F600\nG0 Z0\nM5\nT2 M6\nM3\nG0 X20\nG1 Z-5 F600\nG0 Z-1\nM30\n"


def wait_for_pause(run, timeout: float = 20.0):
    deadline = time.monotonic() + timeout
    while run.pause is None:
        assert run.wait(0.01) is None, "the job ended before its tool change"
        assert time.monotonic() < deadline
    return run.pause


def jog_z(machine: Machine, mm: float):
    """A straight move of Z by `mm`, planned from where the machine stands."""
    start = machine.config.to_mm(machine.position)
    program = parse_gcode(f"G91 G1 Z{mm} F600", machine.config.axis_names, start)
    return machine.move(plan_program(program, machine.config, machine.position).segments)


def test_jog_and_zero_z_at_a_tool_change_then_go_on(start_emulator, tmp_path: Path) -> None:
    job_file = tmp_path / "tools.nc"
    job_file.write_text(JOB)
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)  # real time: the jog takes a while
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        job = load_job(job_file, CONFIG, machine.position, coordinates=machine.coordinates)
        run = machine.run_job(job.plan, job.program)
        pause = wait_for_pause(run)
        assert (pause.line, pause.tool, pause.reason) == (7, 2, "tool change to T2")
        assert run.gives_way
        motion = jog_z(machine, -3.0)  # the new tool is 3 mm longer: touch it to the stock
        assert not run.resume()  # not while the jog runs (0.3 s in real time)
        with pytest.raises(MachineError):
            machine.set_work_zero([2])
        assert motion.wait(10) is not None
        assert machine.position[2] == CONFIG.to_steps((0, 0, -3.0))[2]
        machine.set_work_zero([2])
        assert run.resume()
        end = run.wait(20)
        assert end is not None and end.ended_by == "done", end
        # after the change every Z of the job is 3 mm lower: Z-1 ends at machine Z -4
        assert machine.position == CONFIG.to_steps((20.0, 10.0, -4.0))
        assert job.end_coordinates.offsets[0]["Z"] == pytest.approx(-3.0)


def test_resume_without_changes_keeps_the_plan(start_emulator, tmp_path: Path) -> None:
    job_file = tmp_path / "tools.nc"
    job_file.write_text(JOB)
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        job = load_job(job_file, CONFIG, machine.position, coordinates=machine.coordinates)
        run = machine.run_job(job.plan, job.program)
        wait_for_pause(run)
        planned = run.plan
        assert run.resume()
        end = run.wait(20)
        assert end is not None and end.ended_by == "done"
        assert run.plan is planned
        assert machine.position == job.plan.end
