"""A job's G92/G10/G54…G59 become the machine's work coordinates when the job completes, and only
then: the machine decides it, for the CLI, the TUI and a sender alike (emulator, machine layer)."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine

ROUTER = Path(__file__).resolve().parents[2] / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
JOB = "G21 G90 G54\nG0 X10\nG10 L2 P2 X5\nG55\nG1 X20 F3000\nG1 X0\n"


def run_job_file(tmp_path: Path, emu_url: str, stop_early: bool) -> tuple[str, str, str]:
    job_file = tmp_path / "offsets.nc"
    job_file.write_text(JOB)
    with Link.open(emu_url) as link:
        machine = Machine(link, CONFIG)
        before = machine.coordinates.name
        job = load_job(job_file, CONFIG, machine.position, coordinates=machine.coordinates)
        assert job.end_coordinates.name == "G55"
        run = machine.run_job(job.plan, job.program, leaves=job.end_coordinates)
        if stop_early:
            run.halt()
        end = run.wait(30)
        assert end is not None
        return before, end.ended_by, machine.coordinates.name


def test_a_completed_job_leaves_its_coordinates(start_emulator, tmp_path: Path) -> None:
    emu = start_emulator(axes=3, free=True, tick_hz=CONFIG.tick_hz)
    before, ended_by, after = run_job_file(tmp_path, emu.url, stop_early=False)
    assert (before, ended_by, after) == ("G54", "done", "G55")


def test_a_stopped_job_leaves_the_coordinates_as_they_were(start_emulator, tmp_path: Path) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)  # real time: stopped on its way
    before, ended_by, after = run_job_file(tmp_path, emu.url, stop_early=True)
    assert ended_by != "done"
    assert (before, after) == ("G54", "G54")
