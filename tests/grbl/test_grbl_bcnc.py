"""bCNC (PyPI `bCNC`), its own Sender and GRBL1 controller run headless (tests/helpers/bcnc_stream.py,
in a process of its own), streams a CAM job with a work offset and arcs through `quadstep grbl` on
TCP (bCNC's socket://) and on the pseudo-terminal, to the real emulator with a simulated touch plate;
the machine ends on the steps an independent reading of the file gives, bCNC reads the same position,
and a G38.2 afterwards gives bCNC the plate's height within a step. Skipped when bCNC is not
installed."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_door import CAM_JOB, probe_sim, serving

from quadstep.config import load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.grbl.server import TcpServer
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec("bCNC") is None, reason="bCNC is not installed (pip install bCNC)"
)

REPO = Path(__file__).resolve().parents[2]
HELPER = REPO / "tests" / "helpers" / "bcnc_stream.py"
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
PLATE_Z = -16000.5  # motor steps: a touch plate under X 150…200 mm, Y 100…150 mm
SIM = probe_sim(f"""\
[[probe.target]]
kind = "plate"
z = {PLATE_Z}
x_min = 60000
x_max = 80000
y_min = 40000
y_max = 60000
""")
PROBE = ["G53 G0 X175 Y125", "G38.2 Z-50 F200"]


@pytest.fixture
def machine(start_emulator, tmp_path: Path) -> Iterator[Machine]:
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        axes=3, tick_hz=CONFIG.tick_hz, free=True, queue=16, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        yield Machine(link, CONFIG)


def bcnc(url: str, job: Path) -> dict:
    result = subprocess.run(
        [sys.executable, str(HELPER), url, str(job), *PROBE],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=job.parent,
    )
    assert result.returncode == 0, result.stderr[-3000:] + result.stdout[-3000:]
    line = next(x for x in result.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line.removeprefix("RESULT "))


def check(machine: Machine, said: dict, tmp_path: Path) -> None:
    job = tmp_path / "cam.nc"
    end = load_job(job, CONFIG, (0, 0, 0), coordinates=WorkCoordinates()).plan.end
    assert said["errors"] == []
    assert said["counted"] == said["expected"]
    assert said["machine"] == [round(x, 3) for x in CONFIG.to_mm(end)]
    assert said["work"] == [12.5, 7.25, 5.0]
    (probed,) = said["probed"]
    assert probed[:2] == [175.0, 125.0]
    assert abs(probed[2] * 400 - PLATE_Z) <= 1.0
    assert tuple(machine.link.status().position[:2]) == CONFIG.to_steps((175.0, 125.0, 0.0))[:2]


def test_bcnc_streams_a_cam_job_over_tcp(machine: Machine, tmp_path: Path) -> None:
    (tmp_path / "cam.nc").write_text(CAM_JOB)
    tcp = TcpServer(machine, 0).start()
    try:
        said = bcnc(f"socket://127.0.0.1:{tcp.port}", tmp_path / "cam.nc")
    finally:
        tcp.close()
    check(machine, said, tmp_path)


def test_bcnc_streams_a_cam_job_on_the_pseudo_terminal(machine: Machine, tmp_path: Path) -> None:
    (tmp_path / "cam.nc").write_text(CAM_JOB)
    with serving(machine) as pty:
        said = bcnc(str(pty.path), tmp_path / "cam.nc")
    check(machine, said, tmp_path)
