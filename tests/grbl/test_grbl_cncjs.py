"""CNCjs (npm `cncjs`, installed by `make test` into build/cncjs): its own server and Grbl
controller, driven over Socket.IO as its web page drives them (tests/helpers/cncjs_drive.js), on
`quadstep grbl`'s pseudo-terminal, to the real emulator paced in real time with a surface to probe.

- a CAM job with a work offset and arcs, streamed by CNCjs's sender (character counting), with a
  feed hold and a cycle start from CNCjs in the middle: the machine ends on the steps an
  independent reading of the file gives, and CNCjs reads the same position;
- CNCjs's height map (autolevel) over a surface with a step in it: every height it records is the
  surface's, within a motor step;
- a jog cancelled by CNCjs's jog cancel: it stops short of its end, at rest where CNCjs reads it;
- on the example router's simulated machine (switches, backlash): CNCjs's homing, a work zero from
  its console, then a job with reversals: the carriages end where CNCjs reads the machine;
- a LightBurn-style laser raster run from CNCjs: RASTER lines, never dry, every step predicted.

Skipped when CNCjs is not installed (`make test` installs it)."""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_door import CAM_JOB, probe_sim, serving
from host_helpers import assert_trace_is_prediction
from laser_raster import raster_gcode, record_jobs

from quadstep.config import BacklashConfig, load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.protocol.raster import RasterLine

REPO = Path(__file__).resolve().parents[2]
CNCJS = REPO / "build" / "cncjs" / "node_modules"
DRIVER = REPO / "tests" / "helpers" / "cncjs_drive.js"
pytestmark = pytest.mark.skipif(
    not (CNCJS / ".bin" / "cncjs").exists() or shutil.which("node") is None,
    reason="CNCjs is not installed (make setup-senders)",
)

CONFIG = load_config(REPO / "examples" / "router-uno.toml")
STEPS_PER_MM = 400
PLATE_Z = -16000.5  # motor steps: a plate under X 100…200 mm, Y 80…150 mm
BLOCK_Z = -15000.5  # and a block on it under X 120…160 mm, Y 95…115 mm, 2.5 mm higher
SIM = probe_sim(f"""\
[[probe.target]]
kind = "plate"
z = {PLATE_Z}
x_min = 40000
x_max = 80000
y_min = 32000
y_max = 60000
[[probe.target]]
kind = "block"
z = {BLOCK_Z}
x_min = 48000
x_max = 64000
y_min = 38000
y_max = 46000
""")


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture
def machine(start_emulator, tmp_path: Path) -> Iterator[Machine]:
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        axes=3, tick_hz=CONFIG.tick_hz, queue=14, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        yield Machine(link, CONFIG)


@pytest.fixture
def cncjs(tmp_path: Path) -> Iterator[tuple[str, str]]:
    """A CNCjs server on loopback with a configuration of its own: (its URL, its secret)."""
    secret = "quadstep-tests"
    config = tmp_path / "cncrc"
    config.write_text(json.dumps({"secret": secret, "ports": [], "watchDirectory": ""}))
    port = free_port()
    log = (tmp_path / "cncjs.log").open("w")
    server = subprocess.Popen(
        [str(CNCJS / ".bin" / "cncjs"), "-p", str(port), "-H", "127.0.0.1", "-c", str(config)],
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 60
        while True:
            assert server.poll() is None, (tmp_path / "cncjs.log").read_text()
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.monotonic() < deadline, "CNCjs did not start listening"
                time.sleep(0.1)
        yield f"http://127.0.0.1:{port}", secret
    finally:
        server.terminate()
        server.wait(timeout=10)
        log.close()


def drive(cncjs: tuple[str, str], port: Path, scenario: str, **args: object) -> dict:
    url, secret = cncjs
    result = subprocess.run(
        ["node", str(DRIVER), url, secret, str(port), scenario, json.dumps(args)],
        capture_output=True,
        text=True,
        timeout=240,
        env={**os.environ, "NODE_PATH": str(CNCJS)},
    )
    line = next((x for x in result.stdout.splitlines() if x.startswith("RESULT ")), None)
    assert result.returncode == 0 and line is not None, (
        result.stderr[-3000:] + result.stdout[-3000:]
    )
    return json.loads(line.removeprefix("RESULT "))


def mm(values: dict[str, str]) -> list[float]:
    return [float(values[a]) for a in "xyz"]


def test_cncjs_streams_a_cam_job_through_a_feed_hold(
    machine: Machine, cncjs: tuple[str, str], tmp_path: Path
) -> None:
    job = tmp_path / "cam.nc"
    job.write_text(CAM_JOB)
    with serving(machine) as pty:
        said = drive(cncjs, pty.path, "stream", file=str(job), holdAt=9, holdMs=700)
    end = load_job(job, CONFIG, (0, 0, 0), coordinates=WorkCoordinates()).plan.end
    assert said["errors"] == []
    assert said["sender"]["received"] == said["sender"]["total"]
    assert "Hold" in said["states"] and said["states"][-1] == "Idle"
    assert mm(said["status"]["mpos"]) == [round(x, 3) for x in CONFIG.to_mm(end)]
    assert mm(said["status"]["wpos"]) == [12.5, 7.25, 5.0]
    assert tuple(machine.link.status().position[:3]) == tuple(end)
    assert "[MSG:Pgm End]" in said["messages"]


def test_cncjs_height_map_reads_the_surface_within_a_step(
    machine: Machine, cncjs: tuple[str, str]
) -> None:
    params = {
        "startX": 110, "endX": 150, "stepX": 20,
        "startY": 100, "endY": 110, "stepY": 10,
        "clearanceZ": -30, "startZ": -34, "endZ": -45, "feedrate": 300,
    }  # fmt: skip
    with serving(machine) as pty:
        said = drive(cncjs, pty.path, "autolevel", params=params)
    assert said["errors"] == []
    heights = {(p["x"], p["y"]): p["z"] for p in said["probed"]}
    assert sorted(heights) == [(x, y) for x in (110, 130, 150) for y in (100, 110)]
    for (x, y), z in heights.items():
        surface = BLOCK_Z if 120 <= x <= 160 and 95 <= y <= 115 else PLATE_Z
        assert abs(z * STEPS_PER_MM - surface) <= 1.0, (x, y, z)
    assert len([m for m in said["messages"] if m.startswith("[PRB:")]) == 6
    assert mm(said["status"]["mpos"]) == [150.0, 110.0, -30.0]


def test_cncjs_jog_cancel_stops_short_at_rest(machine: Machine, cncjs: tuple[str, str]) -> None:
    with serving(machine) as pty:
        said = drive(cncjs, pty.path, "jog", line="$J=G91 G21 X100 F1200", cancelMs=300)
    assert said["errors"] == []
    assert said["states"][-2:] == ["Jog", "Idle"]
    x, y, z = mm(said["status"]["mpos"])
    assert 1.0 < x < 50.0 and (y, z) == (0.0, 0.0)  # 20 mm/s for about 0.3 s, not the whole 100 mm
    steps = machine.link.status().position[:3]
    assert [round(s / STEPS_PER_MM, 3) for s in steps] == [x, y, z]


ROUTER_SIM = REPO / "examples" / "router-uno-machine.toml"  # switches, backlash, plates
SIM_BACKLASH = (10.5, 6.25, 3.0)  # its backlash, steps: the configuration compensates it
AFTER_HOMING = """\
G21 G90 G54
G0 X0 Y0 Z2
G1 Z-1 F300
G2 X10 Y0 I5 J0 F1200
G1 Y-5
G0 Z2
G0 X3 Y4
"""


def test_cncjs_homes_sets_a_work_zero_and_runs_a_job_on_a_machine_with_backlash(
    start_emulator, cncjs: tuple[str, str], tmp_path: Path
) -> None:
    job = tmp_path / "after-homing.nc"
    job.write_text(AFTER_HOMING)
    before = [["homing"], ["gcode", "G0 X20 Y30 Z-10"], ["gcode", "G10 L20 P1 X0 Y0 Z0"]]
    emu = start_emulator(
        axes=3, tick_hz=CONFIG.tick_hz, queue=14, extra_args=["--machine", str(ROUTER_SIM)]
    )
    axes = tuple(
        axis.model_copy(update={"backlash": BacklashConfig(mm=steps / STEPS_PER_MM)})
        for axis, steps in zip(CONFIG.axes, SIM_BACKLASH)
    )
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG.model_copy(update={"axes": axes}))
        with serving(machine) as pty:
            said = drive(cncjs, pty.path, "stream", file=str(job), before=before)
        motors = link.status().position[:3]
    carriages = [axis["carriage"] for axis in emu.stop()["machine"]["axes"]]
    assert said["errors"] == []
    assert "Home" in said["states"] and said["states"][-1] == "Idle"
    assert mm(said["status"]["wco"]) == [20.0, 30.0, -10.0]
    assert mm(said["status"]["wpos"]) == [3.0, 4.0, 2.0]
    assert mm(said["status"]["mpos"]) == [23.0, 34.0, -8.0]
    # the carriages where CNCjs reads the machine, the backlash taken up at every reversal (the
    # motors are off by the take-ups): within a step of machine zero's switch point, and half a
    # step more where the simulated backlash is a fraction of a step the take-up rounds (the
    # simulated machine counts from the switches, machine zero counts from the pull-off off them)
    switches = [axis.to_steps(axis.switch_at or 0.0) for axis in CONFIG.axes]
    target = tuple(s - z for s, z in zip(CONFIG.to_steps((23.0, 34.0, -8.0)), switches))
    assert tuple(motors) != target
    assert all(abs(c - t) <= 1.5 for c, t in zip(carriages, target)), carriages


@pytest.mark.realtime
def test_cncjs_streams_a_laser_raster_that_goes_out_as_raster_lines(
    start_emulator, cncjs: tuple[str, str], tmp_path: Path
) -> None:
    """A LightBurn-style grayscale fill (a `G1 X… S…` a pixel, M4) loaded into CNCjs and run from
    it, on the laser Uno's configuration: the rows go out as RASTER lines, the board never runs dry,
    every step is the host's prediction of what it was sent and the machine ends where the file
    does."""
    laser = load_config(REPO / "examples" / "laser-uno.toml")
    job = tmp_path / "raster.nc"
    job.write_text("\n".join(raster_gcode(rows=6, pixels=160)) + "\n")
    trace = tmp_path / "trace.csv"
    emu = start_emulator(axes=3, tick_hz=laser.tick_hz, queue=14, trace=trace)
    with Link.open(emu.url) as link:
        machine = Machine(link, laser)
        jobs = record_jobs(machine)
        with serving(machine) as pty:
            said = drive(cncjs, pty.path, "stream", file=str(job))
        motors = tuple(link.status().position[:3])
    emu.stop()
    assert said["errors"] == []
    assert motors == load_job(job, laser, (0, 0, 0)).plan.end
    assert mm(said["status"]["mpos"]) == [0.0, 0.0, 0.0]
    assert jobs and all(j.state is JobState.DONE and j.states.starvations == 0 for j in jobs)
    sent = [segment for j in jobs for segment in j.plan.segments.segments()]
    assert sum(len(s.raster.power) for s in sent if isinstance(s, RasterLine)) >= 6 * 160
    assert_trace_is_prediction(trace, sent, axis_count=3)
