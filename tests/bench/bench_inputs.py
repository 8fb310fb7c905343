#!/usr/bin/env python3
"""Inputs, latches and homing: figures for docs/INPUTS.md.

Homing repeatability over many homings from random power-up positions of the simulated machine (the emulator,
free-running), with clean switches and with bouncing, glitching ones; on the real Uno binary in simavr the cost of
a trigger's tick and how late the latch is when the pin changes at any phase of the tick.

    python3 tests/bench/bench_inputs.py [--homings N] [--quick]
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "simavr"))
sys.path.insert(0, str(REPO / "tests" / "helpers"))

import avr_sim  # noqa: E402
from machine_helpers import along  # noqa: E402
from quadstep.config import load_config, parse_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.link import Link, until_input  # noqa: E402
from quadstep.machine import Target, open_machine  # noqa: E402
from quadstep.machine.homing import home  # noqa: E402
from quadstep.protocol import Input, Probe  # noqa: E402

CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SWITCH = """
seed = {seed}
[[axis]]
start = {start}
backlash = {backlash}
hard_min = -2000
[axis.limit_min]
at = 0.0
hysteresis = 8
bounce = {bounce}
bounce_ticks = 120
glitch = {glitch}
glitch_ticks = 3
jitter = {jitter}
[[axis]]
[[axis]]
"""


def homed_zero(work: Path, seed: int, noisy: bool) -> tuple[float, int]:
    """Home X once from a random start; returns the backlash and the motor step (the simulation's) that machine
    zero is on."""
    rng = random.Random(seed)
    backlash = rng.choice([0, 3.5, 10.25])
    text = SWITCH.format(seed=seed, start=rng.randint(200, 100_000), backlash=backlash,
                         bounce=3 if noisy else 0, glitch=0.0002 if noisy else 0, jitter=0.3 if noisy else 0)
    path = work / f"m{seed}.toml"
    path.write_text(text)
    data = CONFIG.model_dump()
    data["inputs"]["debounce_ms"] = 5.0 if noisy else 0.0  # 160 ticks: longer than the bounce
    config = parse_config(data)
    emu = Emulator(free=True, tick_hz=config.tick_hz, axes=3, queue=16, extra_args=["--machine", str(path)]).start()
    machine = open_machine(Target(emulator=True), config, emulator=emu)
    try:
        home(machine, ["X"])
        position = machine.position[0]
    finally:
        machine.close()
    motor = emu.stop()["machine"]["axes"][0]["motor"]
    return backlash, motor - position


def homing(count: int) -> None:
    print(f"homing repeatability: X homed {count} times from random power-up positions (0.5 to 250 mm from the "
          "switch, backlash 0, 3.5 or 10.25 steps): machine zero in motor steps")
    with tempfile.TemporaryDirectory() as tmp:
        for noisy in (False, True):
            by_backlash: dict[float, list[int]] = {}
            for seed in range(count):
                backlash, zero = homed_zero(Path(tmp), seed, noisy)
                by_backlash.setdefault(backlash, []).append(zero)
            spread = max(max(z) - min(z) for z in by_backlash.values())
            label = ("bouncing (3 extra contacts in 120 ticks), glitching and jittering (0.3 step) switch, 5 ms "
                     "debounce" if noisy else "clean switch, no debounce")
            print(f"  {label}: spread {spread} step(s) within each backlash; zeros seen: "
                  + ", ".join(f"backlash {b:g}: {sorted(set(z))}" for b, z in sorted(by_backlash.items())))


def trigger_cost() -> None:
    """The Uno's trigger tick and latch lateness, on the real binary."""
    machine = "[[axis]]\nstart = 2400\n[axis.limit_min]\nat = 0.0\n[[axis]]\n[[axis]]\n"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "m.toml"
        path.write_text(machine)
        tick_hz = avr_sim.avr_define("QS_TICK_HZ")
        period = avr_sim.F_CPU // tick_hz
        print(f"on the Uno binary in simavr ({tick_hz} Hz: {period} cycles a tick), a homing seek at 40 mm/s:")
        for delay in (0, period // 5, period // 2, 4 * period // 5, period - 1):
            out = avr_sim.Outputs.in_dir(Path(tmp), f"d{delay}")
            with avr_sim.SimAvr(out, board="uno", extra_args=["--machine", str(path), "--input-delay", str(delay)]) as sim:
                with Link.open(sim.url) as link:
                    until_input(link, Probe(input=Input.LIMIT_0, level=1, decel=(3000, 3000, 3000, 0)),
                                along(0, (0, 0, 0), -8, 40), timeout=60)
            stats = out.load_stats()
            edge = stats["input_edges"][0]
            print(f"  pin {delay:3} cycles after the step: latched {edge['latch_tick'] - edge['tick']} tick(s) "
                  f"after the edge's, the latching interrupt began {edge['latch_cycle'] - edge['cycle']:5} cycles "
                  f"after the edge; longest tick interrupt {stats['isr']['timer']['max']} cycles, "
                  f"{stats['motion']['ticks_missed']} timer period(s) lost")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--homings", type=int, default=100)
    parser.add_argument("--quick", action="store_true", help="20 homings")
    args = parser.parse_args()
    avr_sim.build("firmware", "harness", "emulator")
    homing(20 if args.quick else args.homings)
    trigger_cost()
    print("(the segment rate with the inputs sampled: tests/bench/bench_avr.py; the sample's 3 cycles a tick: "
          "tests/simavr/test_avr_inputs.py)")


if __name__ == "__main__":
    main()
