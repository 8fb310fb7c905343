#!/usr/bin/env python3
"""Jog stop latency on the emulator paced at real time.

    python3 tests/bench/bench_jog.py [--jogs N] [--tui-jogs N] [--release-jogs N] [--seed S]

Continuous jogs on a router-like machine, each ended at a random moment,
half by releasing the key (release detected by the repeat timeout) and half
by the stop key. For each: the time from the stop event (the moment the
release is detected or the stop key acts, time.monotonic_ns) to the first
tick of deceleration (the emulator's --events log, CLOCK_MONOTONIC, the same
clock), and the distance travelled after the stop event (the step trace),
checked against speed × latency + braking distance. Then the stop key
through the whole TUI (Textual, headless): from the key event entering the
app to the first tick of deceleration. Last, a key release through a real
terminal, both ways (bench_release.py): a kitty-protocol release event, and
the repeat timeout. Prints figures only.
"""

from __future__ import annotations

import argparse
import asyncio
import random
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from quadstep.config import MachineConfig, parse_config
from quadstep.emulator import Emulator
from quadstep.jog import JogMode, Jogger, JogSettings
from quadstep.machine import Machine
from quadstep.machine.units import DECEL_SHIFT, braking_steps, hold_decels
from quadstep.link import Link
from quadstep.protocol import SetPosition
from quadstep.kernel.fixed import D

from bench_release import release_latencies

# The router of examples/router-uno.toml: 400 steps/mm leadscrews.
MACHINE: dict[str, Any] = {
    "tick_hz": 50000,
    "axes": [
        {"name": "X", "steps_per_mm": 400, "max_speed": 40, "max_accel": 500, "travel_min": 0, "travel_max": 300},
        {"name": "Y", "steps_per_mm": 400, "max_speed": 40, "max_accel": 500, "travel_min": 0, "travel_max": 200},
        {"name": "Z", "steps_per_mm": 400, "max_speed": 15, "max_accel": 200, "travel_min": -60, "travel_max": 0},
    ],
}
START_MM = (150.0, 100.0, -30.0)
SETTINGS = JogSettings(first_repeat_timeout=0.5, repeat_timeout=0.1)
REPEAT_INTERVAL = 0.033  # s: a terminal repeating at 30 Hz
FIRST_REPEAT = 0.3  # s: its initial repeat delay
# The firmware rounds a HOLD deceleration down to its quantum, at most 2^11/(k·n) ≤ 4 units (k·n ≥ 512).
DECEL_QUANTUM_LOSS = 4


@dataclass
class Jog:
    axis: int
    speed: float  # jog speed, steps per tick
    way: str
    stop_ns: int
    hold_tick: int
    end_tick: int  # motion ticks when the machine rested
    rest: int  # rest position of the axis


def run_jogs(count: int, seed: int, config: MachineConfig, events: Path, trace: Path) -> tuple[list[Jog], int]:
    rng = random.Random(seed)
    jogs: list[Jog] = []
    with Emulator(free=False, axes=3, trace=trace, extra_args=("--events", str(events))) as emu:
        with Link.open(emu.url) as link:
            start = config.to_steps(START_MM)
            link.send(SetPosition(positions=dict(enumerate(start))))
            link.drain()
            jogger = Jogger(Machine(link, config), SETTINGS)
            jogger.mode = JogMode.CONTINUOUS
            for i in range(count):
                axis = i % 3
                direction = 1 if (i // 3) % 2 == 0 else -1  # back and forth around the middle
                jogger.speed_index = rng.choice((2, 3, 4))  # 25, 50, 100 % of the axis max
                moving = rng.uniform(0.05, 0.6)
                way = "release" if i % 2 else "stop key"
                jogger.press(axis, direction)
                if way == "release":
                    until = time.monotonic() + moving
                    time.sleep(min(FIRST_REPEAT, moving))
                    while time.monotonic() < until:
                        jogger.press(axis, direction)
                        time.sleep(REPEAT_INTERVAL)
                else:
                    time.sleep(moving)
                    jogger.stop()
                jogger.wait_idle()
                result = jogger.last_result
                assert result is not None and result.end is not None
                end = result.end
                if not end.held or end.stop_event_ns is None or end.hold_tick is None:
                    raise SystemExit(f"jog {i} did not end with a HOLD: {result}")
                cfg = config.axes[axis]
                speed = jogger.speed(axis) * cfg.steps_per_mm / config.tick_hz
                jogs.append(Jog(axis, speed, way, end.stop_event_ns, end.hold_tick,
                                link.status().motion_ticks, result.position[axis]))
            retransmits = link.stats.retransmits
    return jogs, retransmits


async def tui_stop_keys(count: int, seed: int, config: MachineConfig, events: Path) -> list[float]:
    """Stop-key latency through the whole TUI: from the key event entering the app to the first decel tick."""
    from textual import events as textual_events

    from quadstep.tui import QuadstepApp, Session, Target

    rng = random.Random(seed)
    options = {"free": False, "axes": 3, "extra_args": ("--events", str(events))}
    session = Session(Target(emulator=True, emulator_options=options), config, SETTINGS)
    app = QuadstepApp(session)
    pressed: list[tuple[int, int]] = []  # (key event ns, hold tick)
    async with app.run_test(size=(100, 30)) as pilot:
        while not (session.connected and app.machine.snapshot is not None):
            await pilot.pause(0.05)
        jogger = session.jogger
        assert jogger is not None
        start = config.to_steps(START_MM)
        jogger.machine.set_position(dict(enumerate(start)))
        jogger.sync()
        jogger.mode = JogMode.CONTINUOUS
        for i in range(count):
            key = ("right", "left")[i % 2]
            app.post_message(textual_events.Key(key, None))
            await asyncio.sleep(rng.uniform(0.1, 0.4))  # within the first-repeat timeout: only the key stops it
            stop_ns = time.monotonic_ns()
            app.post_message(textual_events.Key("space", " "))
            while jogger.busy or jogger.last_result is None or jogger.last_result.end is None \
                    or jogger.last_result.end.stop_event_ns is None or jogger.last_result.end.stop_event_ns < stop_ns:
                await asyncio.sleep(0.01)
            end = jogger.last_result.end
            if not end.held or end.hold_tick is None:
                raise SystemExit(f"TUI jog {i} did not end with a HOLD: {jogger.last_result}")
            pressed.append((stop_ns, end.hold_tick))
    holds = read_events(events)
    return [(holds[tick] - ns) / 1e6 for ns, tick in pressed]


def read_events(path: Path) -> dict[int, int]:
    holds = {}
    for line in path.read_text().splitlines()[1:]:
        kind, tick, ns = line.split(",")
        if kind == "hold":
            holds[int(tick)] = int(ns)
    return holds


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(np.array(values), q))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jogs", type=int, default=60)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--tui-jogs", type=int, default=20, help="stop-key jogs through the TUI")
    parser.add_argument("--release-jogs", type=int, default=15,
                        help="jogs ended by a release through a terminal, each way (kitty, repeat timeout)")
    args = parser.parse_args()
    config = parse_config(MACHINE, "bench machine")
    decels = hold_decels(config)
    with tempfile.TemporaryDirectory() as tmp:
        events, trace = Path(tmp) / "events.csv", Path(tmp) / "trace.csv"
        wall = time.monotonic()
        jogs, retransmits = run_jogs(args.jogs, args.seed, config, events, trace)
        wall = time.monotonic() - wall
        holds = read_events(events)
        steps = np.loadtxt(trace, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2)

    latencies: list[float] = []  # ms
    travel: list[float] = []  # steps after the stop event
    violations: list[str] = []
    previous_end = 0
    for i, jog in enumerate(jogs):
        if jog.hold_tick not in holds:
            raise SystemExit(f"jog {i}: no hold at tick {jog.hold_tick} in the events log")
        latency_ns = holds[jog.hold_tick] - jog.stop_ns
        latencies.append(latency_ns / 1e6)
        stop_tick = jog.hold_tick - round(latency_ns * MACHINE["tick_hz"] / 1e9)  # motion tick at the stop event
        mine = steps[(steps[:, 0] > max(stop_tick, previous_end)) & (steps[:, 0] <= jog.end_tick)
                     & (steps[:, 1] == jog.axis)]
        after = int(len(mine))
        travel.append(after)
        ticks = max(0, jog.hold_tick - stop_tick)
        v = jog.speed + 1 / D  # speeds are whole 1/4096 step per tick: allow one quantum
        bound = v * ticks + braking_steps(v, decels[jog.axis] - DECEL_QUANTUM_LOSS) + 1
        if after > bound:
            violations.append(f"jog {i} ({'XYZ'[jog.axis]}, {jog.way}): {after} steps after the stop event, "
                              f"bound {bound:.1f}")
        previous_end = jog.end_tick

    spm = MACHINE["axes"][0]["steps_per_mm"]
    print("== jog stop latency ==            (emulator paced at 50 kHz, 2-core shared machine; varies with load)")
    print(f"jogs                          {len(jogs)} continuous ({sum(j.way == 'release' for j in jogs)} ended by "
          f"release, {sum(j.way == 'stop key' for j in jogs)} by the stop key), {wall:.0f} s, "
          f"{retransmits} retransmits")
    print(f"release detection             no repeat within {SETTINGS.first_repeat_timeout:g} s of the press, "
          f"{SETTINGS.repeat_timeout:g} s of a repeat (the terminal sends no release)")
    print("stop event → first decel tick "
          f"median {statistics.median(latencies):.1f} ms, p90 {percentile(latencies, 90):.1f} ms, "
          f"worst {max(latencies):.1f} ms, best {min(latencies):.1f} ms")
    print(f"travel after the stop event   median {statistics.median(travel):.0f} steps "
          f"({statistics.median(travel) / spm:.3f} mm), worst {max(travel)} steps ({max(travel) / spm:.3f} mm)")
    print(f"  bound speed × latency + braking at the axis max_accel (HOLD decels {decels} × 2^-{DECEL_SHIFT} "
          f"step/tick²): {len(violations)} violations")
    for line in violations:
        print(f"    {line}")
    with tempfile.TemporaryDirectory() as tmp:
        tui = asyncio.run(tui_stop_keys(args.tui_jogs, args.seed, config, Path(tmp) / "events.csv"))
    print(f"stop key through the TUI      median {statistics.median(tui):.1f} ms, p90 {percentile(tui, 90):.1f} ms, "
          f"worst {max(tui):.1f} ms ({len(tui)} jogs: key event into the app → first decel tick)")
    with tempfile.TemporaryDirectory() as tmp:
        kitty = release_latencies(args.release_jogs, args.seed, True, Path(tmp))
        repeats = release_latencies(args.release_jogs, args.seed, False, Path(tmp))
    for name, values in (("kitty release event", kitty), ("repeat timeout", repeats)):
        print(f"{name + ' → decel tick':<34}median {statistics.median(values):.1f} ms, "
              f"p90 {percentile(values, 90):.1f} ms, worst {max(values):.1f} ms ({len(values)} jogs through a pty)")
    print(f"  (the terminal's bytes written → first decel tick; repeat timeout: from the last repeat, "
          f"timeout {JogSettings().repeat_timeout:g} s)")
    print("peers: GRBL jogging guide 0.4–0.9 s typical (jog cancel); UGS sends a jog every 10 ms, then a cancel")


if __name__ == "__main__":
    main()
