#!/usr/bin/env python3
"""Resuming: a job whose port is pulled mid-job (the cable, then plugged in again as a new port), or whose host
is killed (SIGKILL), goes on with `quadstep run JOB --resume` from where motion stopped. Prints, per fault, the
jobs that ended exactly on the file's end, the steps lost, and how far the carriage path strayed from the
uninterrupted job's path (the board's stop brakes each axis at its own max_accel, which may leave the line).

    python3 tests/bench/bench_resume.py [--trials N] [--only drop,kill]

The board is the paced emulator (real time) with the demo job (examples/demo.gcode, about 11 s); each trial
faults once at a random moment between 1 and 9 s. Prints figures only; tests/cli/test_resume.py holds the
pass/fail checks.
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from byte_faults import FaultyLine  # noqa: E402
from host_helpers import read_trace  # noqa: E402

from quadstep.config import MachineConfig, load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.job import load_job  # noqa: E402
from quadstep.link import Link  # noqa: E402
from quadstep.planner.program import LinearMove  # noqa: E402
from quadstep.protocol import State  # noqa: E402

ROUTER = REPO / "examples" / "router-uno.toml"
DEMO = REPO / "examples" / "demo.gcode"


def host(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "quadstep.cli", "run", str(DEMO), "--config", str(ROUTER),
                             *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            text=True, cwd=REPO)


def at_rest(url: str) -> tuple[int, ...]:
    with Link.open(url) as link:
        while True:
            status = link.status()
            if status.state in (State.IDLE, State.ALARM, State.STARVED) and status.queue_fill == 0:
                return tuple(status.position[:3])
            time.sleep(0.05)


def path_points(config: MachineConfig) -> np.ndarray:
    """The job's path as written: the polyline of its moves' targets, in steps."""
    program = load_job(DEMO, config).program
    points = [(0, 0, 0)] + [config.to_steps(i.target) for i in program.items if isinstance(i, LinearMove)]
    return np.asarray(points, dtype=float)


def stray(trace: np.ndarray, polyline: np.ndarray) -> float:
    """The farthest a traced carriage position lies from the polyline, in steps."""
    steps = np.zeros((len(trace), 3))
    steps[np.arange(len(trace)), trace[:, 1]] = trace[:, 2]
    positions = np.cumsum(steps, axis=0)[:: max(1, len(trace) // 20_000)]
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    length = np.maximum((ab**2).sum(axis=1), 1e-12)
    worst = 0.0
    for chunk in np.array_split(positions, max(1, len(positions) // 2000)):
        t = np.clip((((chunk[:, None, :] - a[None]) * ab[None]).sum(axis=2)) / length[None], 0, 1)
        nearest = a[None] + t[..., None] * ab[None]
        worst = max(worst, float(np.sqrt(((chunk[:, None, :] - nearest) ** 2).sum(axis=2)).min(axis=1).max()))
    return worst


def trial(fault: str, rng: random.Random, config: MachineConfig, folder: Path) -> tuple[bool, int, float]:
    trace = folder / f"trace-{time.monotonic_ns()}.csv"
    with Emulator(axes=3, tick_hz=config.tick_hz, trace=trace) as emu:
        line = FaultyLine(emu.url, 0.0)
        process = host("--port", line.port)
        assert process.stdout is not None
        process.stdout.readline()  # streaming begins
        time.sleep(rng.uniform(1.0, 9.0))
        if fault == "drop":
            line.close()
        else:
            process.send_signal(signal.SIGKILL)
        process.communicate(timeout=120)
        line.close()
        with FaultyLine(emu.url, 0.0) as again:
            at_rest(again.port)
            resumed = host("--port", again.port, "--resume")
            resumed.communicate(timeout=300)
            end = at_rest(again.port)
    plan_end = load_job(DEMO, config).plan.end
    lost = int(sum(abs(a - b) for a, b in zip(end, plan_end)))
    return resumed.returncode == 0 and lost == 0, lost, stray(read_trace(trace), path_points(config))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--only", default="drop,kill")
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    config = load_config(ROUTER)
    rng = random.Random(args.seed)
    names = {"drop": "port pulled and plugged in again", "kill": "host SIGKILLed"}
    with tempfile.TemporaryDirectory() as folder:
        os.environ["XDG_STATE_HOME"] = folder
        for fault in args.only.split(","):
            results = [trial(fault, rng, config, Path(folder)) for _ in range(args.trials)]
            exact = sum(ok for ok, _, _ in results)
            print(f"{names[fault]}, {args.trials} trials: {exact} resumed exactly, steps lost "
                  f"{sum(lost for _, lost, _ in results)}, path strayed at most "
                  f"{max(s for _, _, s in results):.1f} steps "
                  f"({max(s for _, _, s in results) / config.axes[0].steps_per_mm * 1000:.0f} µm) from the "
                  "job's polyline", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
