"""Run every benchmark and print its figures (`make bench`).

Each benchmark prints its own figures; none asserts a time. Pass names to run
a subset: `python3 tests/bench/run_all.py host planner`. The figures recorded
from these runs are in docs/BENCHMARKS.md.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BENCH = Path(__file__).resolve().parent

COMMANDS: dict[str, list[str]] = {
    "engine": ["make", "-s", "-C", str(REPO), "bench-engine"],
    "host": [sys.executable, str(BENCH / "bench_host.py")],
    "window": [sys.executable, str(BENCH / "bench_window.py")],
    "planner": [sys.executable, str(BENCH / "bench_planner.py")],
    "avr": [sys.executable, str(BENCH / "bench_avr.py")],
    "hold": [sys.executable, str(BENCH / "bench_hold.py")],
    "jog": [sys.executable, str(BENCH / "bench_jog.py")],
    "cubic": [sys.executable, str(BENCH / "bench_cubic_avr.py")],
    "seed002": [sys.executable, str(BENCH / "bench_seed002.py")],
    "backlash": [sys.executable, str(BENCH / "bench_backlash.py")],
    "scurve": [sys.executable, str(BENCH / "bench_scurve.py")],
    "wire": [sys.executable, str(BENCH / "bench_wire.py")],
    "faults": [sys.executable, str(BENCH / "bench_faults.py")],
    "busy": [sys.executable, str(BENCH / "bench_busy_host.py")],
    "resume": [sys.executable, str(BENCH / "bench_resume.py")],
    "grbl_stream": [sys.executable, str(BENCH / "bench_grbl_stream.py")],
    "tui": [sys.executable, str(BENCH / "bench_tui.py")],
    "fuzz": ["make", "-s", "-C", str(REPO), "fuzz-long"],
}


def main(names: list[str]) -> int:
    unknown = [n for n in names if n not in COMMANDS]
    if unknown:
        print(f"unknown benchmark {', '.join(unknown)}; choose from {', '.join(COMMANDS)}", file=sys.stderr)
        return 2
    failed = []
    for name in names or list(COMMANDS):
        print(f"\n== {name} ==", flush=True)
        if subprocess.run(COMMANDS[name], cwd=REPO).returncode != 0:
            failed.append(name)
    if failed:
        print(f"\nfailed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
