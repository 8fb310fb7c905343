#!/usr/bin/env python3
"""The send window alone, against a model of the firmware over a faulty line (tests/helpers/window_model.py):
randomized scenarios of loss, duplication and reordering of frames and ACKs, no port, no threads.

    python3 tests/bench/bench_window.py [--scenarios N] [--repeat R]

Prints scenarios per second (CPU time of this process, best and median of R runs) and what the
scenarios held; nothing is asserted here (tests/link/test_window.py checks every outcome).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "helpers"))

from window_model import scenario  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    times = []
    for _ in range(args.repeat):
        start = time.process_time()
        outcomes = [scenario(seed) for seed in range(args.scenarios)]
        times.append(time.process_time() - start)
    exact = sum(o.executed == list(range(o.segments)) and o.accepted == o.segments and not o.in_flight
                for o in outcomes)
    lost = [sum(o.lost[d] for o in outcomes) for d in (0, 1)]
    dup = [sum(o.duplicated[d] for o in outcomes) for d in (0, 1)]
    over = [sum(o.overtaken[d] for o in outcomes) for d in (0, 1)]
    print(f"send window, {args.scenarios} randomized scenarios (1-8 segments, queue 1-8, loss up to 40 %, "
          f"duplication up to 30 %, delays that reorder), no port:")
    print(f"  {min(times):.2f} s best, {statistics.median(times):.2f} s median of {args.repeat} "
          f"({args.scenarios / statistics.median(times):,.0f} scenarios/s, CPU time)")
    print(f"  every segment executed exactly once, in order: {exact} of {args.scenarios} scenarios")
    print(f"  {sum(o.segments for o in outcomes)} segments, {sum(o.retransmits for o in outcomes)} retransmits; "
          f"frames lost {lost[0]}, duplicated {dup[0]}, overtaken {over[0]}; "
          f"ACKs lost {lost[1]}, duplicated {dup[1]}, overtaken {over[1]}")


if __name__ == "__main__":
    main()
