"""Files of the shapes real CAM and senders write (tests/gcode/corpus): the GRBL-style ones run, the others are
refused, each with a message that says what the file is.

corpus/grbl holds files GRBL runs: CAM headers (Fusion 360, CamBam, Estlcam, VCarve, Carbide Create, FlatCAM)
with G54/G55, G64/G61, T M6, S M3 and coolant, laser files (Inkscape's laser plugin, LightBurn's M4, a raster),
arcs in every plane, G28/G30/G53/G92, inches, sender-style spacing and case. corpus/refused holds other dialects.
The test prints the fraction of the GRBL-style files that run, then runs each on the emulator (a file that probes
on the example router's simulated machine, with its touch plate): every tool change is continued at once, and
the machine must end exactly where the plan does.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.job import load_job
from quadstep.machine import Machine
from quadstep.link import Link
from quadstep.planner.program import JobError

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
CORPUS = HERE / "corpus"
GRBL_FILES = sorted((CORPUS / "grbl").iterdir())
ROUTER = REPO / "examples" / "router-uno.toml"
REFUSED = {
    "printer-cura.gcode": "line 5, column 1: 'M140' is a 3D printer's code: this is a 3D-printer file",
    "linuxcnc-subroutine.ngc": "line 3, column 1: 'o100': O-word flow control",
    "linuxcnc-parameters.ngc": "line 3, column 1: '#': parameters (variables) are not supported",
    "fanuc-canned-drill.nc": "line 5, column 1: 'G81': canned cycles (G73, G81 … G89) are not supported",
}
SIM = REPO / "examples" / "router-uno-machine.toml"  # a touch plate under the router, for the probing files


def config_for(path: Path, tmp_path: Path):
    """Laser files on a laser machine (GRBL's $32), the others on the router."""
    if not path.name.startswith("laser-"):
        return load_config(ROUTER)
    laser = tmp_path / "laser.toml"
    laser.write_text(ROUTER.read_text() + "\n[spindle]\ns_max = 1000\nlaser = true\n")
    return load_config(laser)


def work_zero() -> WorkCoordinates:
    """G54 where a user would have zeroed: the stock's corner 50 mm in, its top 20 mm below Z's top."""
    coordinates = WorkCoordinates()
    for axis, mm in zip("XYZ", (50.0, 50.0, -20.0)):
        coordinates.set_offset(1, axis, mm)
    return coordinates


def outcome(path: Path, tmp_path: Path) -> str | None:
    try:
        load_job(path, config_for(path, tmp_path), coordinates=work_zero())
    except JobError as exc:
        return str(exc)
    return None


def test_the_grbl_style_files_run(tmp_path: Path) -> None:
    refused = {path.name: outcome(path, tmp_path) for path in GRBL_FILES}
    failed = {name: why for name, why in refused.items() if why is not None}
    runs = len(GRBL_FILES) - len(failed)
    print(f"\ncorpus: {runs} of {len(GRBL_FILES)} GRBL-style files run without --skip-unsupported "
          f"({100 * runs / len(GRBL_FILES):.1f} %)")
    for name, why in failed.items():
        print(f"  refused: {why}")
    assert len(GRBL_FILES) >= 20
    assert not failed
    assert runs / len(GRBL_FILES) >= 0.95


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_other_dialects_are_refused_by_name(name: str, tmp_path: Path) -> None:
    path = CORPUS / "refused" / name
    why = outcome(path, tmp_path)
    assert why is not None and why.startswith(f"{path}: {REFUSED[name]}"), why


@pytest.mark.parametrize("path", GRBL_FILES, ids=lambda p: p.name)
def test_each_file_runs_exactly_on_the_emulator(path: Path, start_emulator, tmp_path: Path) -> None:
    config = config_for(path, tmp_path)
    probes = "G38" in path.read_text()
    emu = start_emulator(free=True, axes=len(config.axes), tick_hz=config.tick_hz,
                         extra_args=["--machine", str(SIM)] if probes else [])
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        machine.adopt_coordinates(work_zero())
        job = load_job(path, config, machine.position, coordinates=machine.coordinates)
        run = machine.run_job(job.plan, job.program)
        tool_changes = 0
        while (end := run.wait(0.02)) is None:
            if run.paused_at is not None and run.resume():
                tool_changes += 1
        assert end.ended_by == "done", end
        if probes:  # planned again from where the probe stopped: the job's own last move is where it ends
            assert machine.position == run.plan.base.end
        else:
            assert machine.position == job.plan.end
            assert tool_changes == len(job.plan.pauses)
