"""Touch-off routines (machine/touch_off.py) on simulated machines: Z on the example router's 10 mm
plate lands the work zero on the surface below it, an edge and a corner of the block land on its faces
(the tool's radius applied toward the face), a bore's and a boss's centre on theirs. The simulated
mechanics have backlash: a face is met, moving toward it, with the motor half the dead band past the
carriage, and that is where the zero must be (within a step)."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import MachineConfig, load_config
from quadstep.machine import Machine, Target, open_machine
from quadstep.machine.touch_off import TouchOff, TouchOffError
from quadstep.planner.plan import plan_program
from quadstep.planner.program import LinearMove, Program
from quadstep.touch_off_settings import TouchOffSettings

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SIM = REPO / "examples" / "router-uno-machine.toml"
STEP = 1 / 400  # mm, every axis of the example router
# power-up motor positions of the example's simulated machine (host step 0 is there)
START = {"X": 40000, "Y": 30000, "Z": -8000}
HALF_BAND = {"X": 10.5 / 2, "Y": 6.25 / 2, "Z": 3.0 / 2}


def met_moving(axis: str, face_motor: float, direction: int) -> float:
    """The host mm at which the tool meets a face (motor steps of the simulated file) moving in
    `direction`: the carriage trails the motor by half the dead band."""
    return (face_motor - START[axis] + direction * HALF_BAND[axis]) * STEP


def sim_with(tmp_path: Path, targets: str) -> Path:
    """The example's simulated machine with other probe targets."""
    text = SIM.read_text().split("[[probe.target]]")[0]
    path = tmp_path / "machine.toml"
    path.write_text(text + targets)
    return path


def open_sim(start_emulator, sim: Path, config: MachineConfig = CONFIG) -> Machine:  # noqa: ANN001
    extra = ["--machine", str(sim)]
    emu = start_emulator(free=True, tick_hz=config.tick_hz, axes=3, queue=16, extra_args=extra)
    return open_machine(Target(emulator=True), config, emulator=emu)


def go(machine: Machine, *moves: tuple[float, float, float]) -> None:
    for target in moves:
        program = Program(items=[LinearMove(line=1, target=target, feed=None)], lines=1)
        plan = plan_program(program, machine.config, machine.sync())
        end = machine.move(plan.segments).wait(60)
        assert end is not None and end.ended_by == "done"


def test_z_on_a_10_mm_plate_zeroes_the_surface_below_it(start_emulator) -> None:  # noqa: ANN001
    machine = open_sim(start_emulator, SIM)
    said: list[str] = []
    try:
        result = TouchOff(machine, TouchOffSettings(plate=10.0), said.append).z()
        # the plate's top at motor -16000.5; the surface it lies on 10 mm (4000 steps) below
        surface = met_moving("Z", -16000.5 - 4000, -1)
        zero = result.zero_mm["Z"]
        assert abs(zero - surface) <= STEP, (zero, surface)
        assert machine.coordinates.offset("Z") == pytest.approx(zero)
        assert machine.work_position[2] == pytest.approx(5.0, abs=STEP)  # the safe height
        assert said == [
            "Z: first touch at 5 mm/s",
            "Z: second touch at 0.5 mm/s",
        ]
        assert result.describe().startswith("Z on a 10 mm plate: work zero in G54 at machine Z")
    finally:
        machine.close()


def test_an_edge_and_a_corner_of_the_block(start_emulator) -> None:  # noqa: ANN001
    machine = open_sim(start_emulator, SIM)
    settings = TouchOffSettings(depth=15.0, offset=20.0, tool_diameter=6.0)
    try:
        touch = TouchOff(machine, settings)
        # the block: motor X 60000 … 80000.5, Y 20000 … 40000, top at Z -12000 (10 mm down)
        go(machine, (40.0, 10.0, 0.0))
        x_face = met_moving("X", 60000, +1)
        edge = touch.edge("X", +1)
        assert abs(edge.zero_mm["X"] - (x_face + 3.0)) <= STEP
        assert machine.position_mm == pytest.approx((x_face - 2.0, 10.0, 0.0), abs=STEP)
        # from outside its back-left corner: X+ toward the left face, Y− toward the back one
        go(machine, (40.0, 35.0, 0.0))
        corner = touch.corner(+1, -1)
        y_face = met_moving("Y", 40000, -1)
        assert abs(corner.zero_mm["X"] - (x_face + 3.0)) <= STEP
        assert abs(corner.zero_mm["Y"] - (y_face - 3.0)) <= STEP
        assert machine.position_mm == pytest.approx(
            (40.0, 35.0, 0.0), abs=STEP
        )  # back at the start
        # over the block, going down touches it: refused, Z back up
        go(machine, (70.0, 10.0, 0.0))
        with pytest.raises(TouchOffError, match="touched going down 15 mm: start beside the stock"):
            touch.edge("X", +1)
        assert machine.position_mm[2] == pytest.approx(0.0)
    finally:
        machine.close()


BORE = """
[[probe.target]]         # a 20 mm bore at machine X 150, Y 100 in a slab 10 mm down
kind = "bore"
x = 100000
y = 70000
radius_x = 4000.25
radius_y = 4000.25
z = -12000
"""

BOSS = """
[[probe.target]]         # a 30 mm boss at machine X 150, Y 100, its top 10 mm down
kind = "block"
x_min = 94000
x_max = 106000
y_min = 64000
y_max = 76000
z = -12000
"""


def test_a_bore_centre(start_emulator, tmp_path: Path) -> None:  # noqa: ANN001
    machine = open_sim(start_emulator, sim_with(tmp_path, BORE))
    try:
        go(machine, (151.3, 97.9, 0.0), (151.3, 97.9, -15.0))
        result = TouchOff(machine, TouchOffSettings(distance=25.0)).bore()
        assert abs(result.zero_mm["X"] - 150.0) <= STEP
        assert abs(result.zero_mm["Y"] - 100.0) <= STEP
        assert machine.work_position[:2] == pytest.approx((0.0, 0.0), abs=STEP)
    finally:
        machine.close()


def test_a_boss_centre(start_emulator, tmp_path: Path) -> None:  # noqa: ANN001
    machine = open_sim(start_emulator, sim_with(tmp_path, BOSS))
    try:
        go(machine, (148.0, 101.5, 0.0))
        settings = TouchOffSettings(depth=15.0, offset=8.0)
        result = TouchOff(machine, settings).boss(30.0)
        # 30 mm across, 12000 steps: the midpoint of the faces met from outside
        assert abs(result.zero_mm["X"] - 150.0) <= STEP
        assert abs(result.zero_mm["Y"] - 100.0) <= STEP
        assert machine.position_mm[2] == pytest.approx(0.0)
    finally:
        machine.close()


def test_the_touch_off_command(emulator_binary: Path) -> None:
    import subprocess
    import sys

    base = [sys.executable, "-m", "quadstep.cli", "touch-off"]
    where = ["--config", str(REPO / "examples" / "router-uno.toml"), "--sim", str(SIM), "--free"]
    done = subprocess.run(base + ["z", "--plate", "10"] + where, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    surface = met_moving("Z", -16000.5 - 4000, -1)
    assert done.stdout.splitlines()[-1] == (
        f"Z on a 10 mm plate: work zero in G54 at machine Z {surface:.4f} mm")
    bad = subprocess.run(base + ["edge", "X"] + where, capture_output=True, text=True, timeout=120)
    assert bad.returncode != 0 and "'X': give X+ or X- (the way toward the face)" in bad.stderr
