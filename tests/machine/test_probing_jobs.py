"""G38.2 inside a job, on the example router's simulated machine: the job rests, probes through the machine
layer, and reads the rest of the file from where the probe stopped (a G10 L20 after it sets the zero there)."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.machine import Target, open_machine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SIM = REPO / "examples" / "router-uno-machine.toml"
TOUCH_OFF = "G21 G90\nG38.2 Z-30 F120\nG10 L20 P1 Z10\nG0 Z15\nG1 X20 F600\nM30\n"  # a 10 mm plate


def run_job(start_emulator, tmp_path: Path, text: str):
    emu = start_emulator(free=True, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=["--machine", str(SIM)])
    machine = open_machine(Target(emulator=True), CONFIG, emulator=emu)
    path = tmp_path / "touch-off.nc"
    path.write_text(text)
    job = load_job(path, CONFIG, machine.position, coordinates=machine.coordinates)
    run = machine.run_job(job.plan, job.program)
    end = run.wait(60)
    return machine, job, end


def test_a_touch_off_in_the_job_sets_z_where_the_probe_stopped(start_emulator, tmp_path: Path) -> None:
    machine, job, end = run_job(start_emulator, tmp_path, TOUCH_OFF)
    try:
        assert end is not None and end.ended_by == "done", end
        x, _, z = machine.position
        assert x == CONFIG.to_steps((20.0, 0, 0))[0]
        rest = z - CONFIG.to_steps((0, 0, 5.0))[2]  # G0 Z15 is 5 mm above where Z read 10: the probe's rest
        assert -8002 - 400 < rest < -8002  # past the contact (-8002 steps), decelerating, within a mm
        # what the job leaves: G54's Z zero 10 mm below the probe's rest
        assert job.end_coordinates.offsets[0]["Z"] == pytest.approx(CONFIG.axes[2].to_mm(rest) - 10.0)
    finally:
        machine.close()


def test_a_probe_that_finds_nothing_ends_the_job_there(start_emulator, tmp_path: Path) -> None:
    machine, _, end = run_job(start_emulator, tmp_path, TOUCH_OFF.replace("Z-30", "Z-10"))
    try:
        assert end is not None and end.ended_by == "error"
        assert end.error == "G38.2: no contact made on the way to X0 Y0 Z-10"
        assert machine.position == CONFIG.to_steps((0, 0, -10.0))  # it went there, and nothing after it ran
    finally:
        machine.close()
