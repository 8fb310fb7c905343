"""A measuring rig on the simulated machine, shared by the backlash tests and benchmark: a block whose −X, −Y
corner the probe measures X and Y at (Z on its top, tested along its −X face), a limit switch per axis with
hysteresis and bounce, and a backlash that only the simulation knows."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from backlash_helpers import TICK_HZ, backlash_config
from quadstep.config import InputsConfig, MachineConfig
from quadstep.emulator import Emulator
from quadstep.machine import Machine, Target, open_machine
from quadstep.machine.backlash import Measurement, measure_with_probe, measure_with_switch

CORNER = 4000  # steps: the block's −X and −Y faces
TOP = -1000  # steps: its top
HYSTERESIS = (6.5, 9.25, 4.75)  # each axis's switch, steps
SWITCH_END = ("min", "min", "max")
# Where the tool starts to measure each axis: 0.5 mm outside the face it touches, 1 mm inside the
# neighbouring face's edge; each axis's switch 5 mm beyond its start, away from the block.
START = ((3800, 4400, -2000), (4400, 3800, -2000), (4400, 6000, -800))
SWITCH_AT = (1800, 1800, 1200)
TEST_AXIS = ("Y", "X", "X")
TOWARD = (1, 1, -1)


def rig_text(axis: int, backlash: tuple[float, float, float], seed: int = 1) -> str:
    """The simulated machine set up to measure `axis`; `backlash` in steps."""
    text = f"seed = {seed}\n"
    for i, (b, start) in enumerate(zip(backlash, START[axis])):
        text += (f"[[axis]]\nstart = {start}\nbacklash = {b}\n[axis.limit_{SWITCH_END[i]}]\nat = {SWITCH_AT[i]}.0\n"
                 f"hysteresis = {HYSTERESIS[i]}\nbounce = 2\nbounce_ticks = 40\n")
    return text + f"""
[probe]
hysteresis = 1.5
[[probe.target]]
kind = "block"
x_min = {CORNER}
x_max = {CORNER + 4000}
y_min = {CORNER}
y_max = {CORNER + 4000}
z = {TOP}
"""


def rig_config(hysteresis_mm: tuple[float, ...] | None = None) -> MachineConfig:
    """The router with backlash configured (its size does not matter to measuring), 2 ms debounce, and each
    switch's calibrated hysteresis."""
    config = backlash_config((0.1, 0.1, 0.1)).model_copy(update={"inputs": InputsConfig(debounce_ms=2)})
    if hysteresis_mm is None:
        return config
    axes = tuple(a.model_copy(update={"backlash": a.backlash.model_copy(update={"switch_hysteresis": h})})
                 for a, h in zip(config.axes, hysteresis_mm))
    return config.model_copy(update={"axes": axes})


@contextmanager
def rig(work: Path, axis: int, backlash: tuple[float, float, float], config: MachineConfig | None = None,
        binary: Path | None = None) -> Iterator[Machine]:
    """A free-running emulator with the rig for `axis`, and a machine connected to it."""
    path = work / f"rig-{axis}.toml"
    path.write_text(rig_text(axis, backlash))
    emu = Emulator(binary=binary, free=True, tick_hz=TICK_HZ, axes=3, extra_args=["--machine", str(path)]).start()
    try:
        with open_machine(Target(emulator=True), config or rig_config(), emulator=emu) as machine:
            yield machine
    finally:
        emu.stop()


def probe(machine: Machine, axis: int, tries: int) -> Measurement:
    return measure_with_probe(machine, "XYZ"[axis], toward=TOWARD[axis], test=TEST_AXIS[axis], test_toward=1,
                              tries=tries)


def switch(machine: Machine, axis: int, tries: int) -> Measurement:
    return measure_with_switch(machine, "XYZ"[axis], end=SWITCH_END[axis], tries=tries, search=8)
