#!/usr/bin/env python3
"""A busy host: `quadstep run` of a real-time job while the host computer is (a) outnumbered by CPU hogs at
its own priority, or (b) frozen again and again for 50–500 ms (SIGSTOP … SIGCONT), as a small single-board
computer that also runs other things. Prints, per condition, the jobs completed exactly, the jobs lost, and how
often the board ran dry and the job went on by itself (starvation pauses).

    python3 tests/bench/bench_busy_host.py [--runs N] [--lines N] [--hogs N] [--only hogs,stalls]

The board is the paced emulator (the board's own time, an Uno's 14-slot queue), run at a higher priority than
the host's load: a real board does not share the host's CPU. Every job is an engraving of short moves
(tests/helpers/fault_jobs.py), the hardest case for a host that falls behind. A job counts as exact when it ends
completed with every axis on the plan's final step (`quadstep run --json`: `exact`). Prints figures only;
tests/machine/test_starvation.py holds the pass/fail checks.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from fault_jobs import engraving  # noqa: E402

from quadstep.config import load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402

ROUTER = REPO / "examples" / "router-uno.toml"
QUEUE = 14  # the Uno's
HOG = "while True: pass"


@dataclass
class Outcome:
    completed: bool
    exact: bool
    starvations: int
    seconds: float
    error: str = ""


def run_job(job: Path, url: str, load: str, hogs: int, rng: random.Random) -> Outcome:
    """One `quadstep run` of `job` under `load` ("hogs" or "stalls")."""
    hog_processes = [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(hogs if load == "hogs" else 0)]
    began = time.monotonic()
    host = subprocess.Popen([sys.executable, "-m", "quadstep.cli", "run", str(job), "--config", str(ROUTER),
                             "--port", url, "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=REPO)
    done = threading.Event()
    staller = threading.Thread(target=stall, args=(host.pid, done, rng), daemon=True)
    if load == "stalls":
        staller.start()
    try:
        out, err = host.communicate(timeout=3600)
    finally:
        done.set()
        if staller.is_alive():
            staller.join()
        for hog in hog_processes:
            hog.kill()
            hog.wait()
    seconds = time.monotonic() - began
    try:
        result = json.loads(out.splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        return Outcome(False, False, 0, seconds, err.strip().splitlines()[-1] if err.strip() else "no result")
    return Outcome(result["completed"], result["exact"], result.get("starvations", 0), seconds)


def stall(pid: int, done: threading.Event, rng: random.Random) -> None:
    """Freeze the host for 50–500 ms, let it run 0.2–1.5 s, again, until it ends."""
    while not done.wait(rng.uniform(0.2, 1.5)):
        try:
            os.kill(pid, signal.SIGSTOP)
            time.sleep(rng.uniform(0.05, 0.5))
            os.kill(pid, signal.SIGCONT)
        except ProcessLookupError:
            return


def condition(load: str, runs: int, lines: int, hogs: int, seed: int) -> list[Outcome]:
    config = load_config(ROUTER)
    rng = random.Random(seed)
    outcomes = []
    with tempfile.TemporaryDirectory() as folder:
        job = Path(folder) / "engraving.gcode"
        job.write_text(engraving(lines))
        os.environ["XDG_STATE_HOME"] = folder  # the runs' state and journals, not the user's
        for k in range(runs):
            with Emulator(axes=3, tick_hz=config.tick_hz, queue=QUEUE) as emu:
                if emu.pid is not None:
                    os.setpriority(os.PRIO_PROCESS, emu.pid, -5)  # the board does not share the host's CPU
                outcome = run_job(job, emu.url, load, hogs, rng)
            outcomes.append(outcome)
            print(f"  {load} run {k + 1}: {'exact' if outcome.exact else 'LOST'}, "
                  f"{outcome.starvations} starvation pauses, {outcome.seconds:.1f} s"
                  f"{'  ' + outcome.error if outcome.error else ''}", flush=True)
    return outcomes


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--lines", type=int, default=3000, help="engraving moves a job")
    parser.add_argument("--hogs", type=int, default=4, help="CPU hogs beside the host process")
    parser.add_argument("--only", default="hogs,stalls")
    parser.add_argument("--seed", type=int, default=19)
    args = parser.parse_args()
    print(f"busy host: {args.runs} runs a condition, engraving of {args.lines} lines, Uno queue {QUEUE}, "
          f"cores {os.cpu_count()}", flush=True)
    for load in args.only.split(","):
        outcomes = condition(load, args.runs, args.lines, args.hogs, args.seed)
        lost = sum(not o.exact for o in outcomes)
        pauses = [o.starvations for o in outcomes]
        label = f"{args.hogs} CPU hogs" if load == "hogs" else "SIGSTOP stalls of 50–500 ms"
        print(f"{label}: {len(outcomes) - lost}/{len(outcomes)} exact, jobs lost {lost}; starvation pauses "
              f"{sum(pauses)} in all (median {sorted(pauses)[len(pauses) // 2]} a job, most {max(pauses)}); "
              f"job time median {sorted(o.seconds for o in outcomes)[len(outcomes) // 2]:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
