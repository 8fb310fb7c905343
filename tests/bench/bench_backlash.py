#!/usr/bin/env python3
"""Backlash: figures for docs/BACKLASH.md, on the emulator with a simulated machine whose backlash only the
simulation knows.

Measurement: random backlash values in 0 … 0.3 mm on each axis, measured with the probe at a block's corner
and with the limit switch (hysteresis and bounce; its hysteresis calibrated once, from the probe's value):
the worst error in steps. Compensation: a circle and a pocket, with and without it: the carriage's path error
from the simulated carriage positions, the job time, and each axis's acceleration during the take-ups (from
the stream's segment states, which the trace matches step for step, and from the trace's own second
differences).

Zigzag: passes back and forth along X that reverse sharply at every tip (a raster's), with a backlash of one
step, 0.05 mm and 0.2 mm on X, and a sawtooth whose Y reverses at wide corners, with it on Y: the job time with
and without it, the carriage's path error, how far it is behind the plan, and where the take-ups went.

    python3 tests/bench/bench_backlash.py [--values N] [--tries K] [--quick] [--only jobs|zigzag|measurement]
"""

from __future__ import annotations

import argparse
import random
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from backlash_helpers import (  # noqa: E402
    STEPS_PER_MM, TICK_HZ, circle_gcode, pocket_gcode, pocket_path, zigzag_gcode, zigzag_path,
)
from backlash_jobs import (  # noqa: E402
    Ran, circle_error, path_error, plan_lag, run_job, stepper_circle_error, takeup_accel,
)
from backlash_rig import HYSTERESIS, SWITCH_END, probe, rig, rig_config, switch  # noqa: E402
from quadstep.kernel.engine_model import predict
from quadstep.machine.backlash import calibrate_switch  # noqa: E402

AXES = "XYZ"
LARGEST = 0.3 * STEPS_PER_MM  # steps
SMOOTHING = TICK_HZ // 100  # 10 ms: the trace's second differences


def calibrated_hysteresis(work: Path, rng: random.Random, tries: int) -> tuple[float, ...]:
    """Each switch's hysteresis (mm), calibrated once as a user would: the backlash measured with the probe,
    then the switch's sum less it."""
    found = []
    for axis in range(3):
        backlash = tuple(rng.uniform(0, LARGEST) for _ in range(3))
        with rig(work, axis, backlash) as machine:
            known = probe(machine, axis, tries).mm
            found.append(calibrate_switch(machine, AXES[axis], known, end=SWITCH_END[axis], tries=tries, search=8))
        print(f"  {AXES[axis]}: calibrated at a backlash of {backlash[axis]:.2f} steps (the probe: "
              f"{known * STEPS_PER_MM:g}): hysteresis {found[-1] * STEPS_PER_MM:.3f} steps, simulated "
              f"{HYSTERESIS[axis]}")
    return tuple(found)


def measurement(values: int, tries: int) -> None:
    rng = random.Random(10)
    print(f"measurement: {values} random backlash values in 0 … 0.3 mm (0 … {LARGEST:g} steps) on each axis, "
          f"{tries} tries each; errors in steps (measured − simulated)")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        hysteresis = calibrated_hysteresis(work, rng, tries)
        config = rig_config(hysteresis)
        errors: dict[str, list[list[float]]] = {"probe": [[], [], []], "switch": [[], [], []], "sum": [[], [], []]}
        spreads = {"probe": 0.0, "switch": 0.0}
        for _ in range(values):
            backlash = tuple(rng.uniform(0, LARGEST) for _ in range(3))
            for axis in range(3):
                with rig(work, axis, backlash, config) as machine:
                    by_probe, by_switch = probe(machine, axis, tries), switch(machine, axis, tries)
                errors["probe"][axis].append(by_probe.steps - backlash[axis])
                errors["switch"][axis].append(by_switch.steps - backlash[axis])
                errors["sum"][axis].append(by_switch.sum_steps - backlash[axis] - HYSTERESIS[axis])
                spreads["probe"] = max(spreads["probe"], by_probe.spread_steps)
                spreads["switch"] = max(spreads["switch"], by_switch.spread_steps)
    labels = {"probe": "probe at the corner", "switch": "switch, calibrated hysteresis taken off",
              "sum": "switch, backlash + hysteresis alone (its rounding)"}
    for method, per_axis in errors.items():
        worst = [max(e, key=abs) for e in per_axis]
        every = [x for e in per_axis for x in e]
        print(f"  {labels[method]}: worst " + ", ".join(f"{AXES[a]} {w:+.3f}" for a, w in enumerate(worst))
              + f"; all within {min(every):+.3f} … {max(every):+.3f} step, mean |error| "
              f"{statistics.fmean(abs(x) for x in every):.2f}")
    print(f"  largest spread over the tries: probe {spreads['probe']:g}, switch {spreads['switch']:g} steps")
    print(f"  calibration's own error (hysteresis found − simulated): "
          + ", ".join(f"{AXES[a]} {h * STEPS_PER_MM - HYSTERESIS[a]:+.2f}" for a, h in enumerate(hysteresis))
          + " step; the switch's error is the sum's rounding less it")


def jobs_figures(quick: bool) -> None:
    jobs = [("circle r = 20 mm, 10 mm/s", circle_gcode(20, 10, turns=1 if quick else 2), "circle"),
            ("pocket 20 × 6 mm, 1.5 mm stepover, 15 mm/s", pocket_gcode(20, 6, 1.5, 15), "pocket")]
    print("compensation: the carriage's path error from the simulated carriage positions (steps; 1 step = "
          f"{1000 / STEPS_PER_MM:g} µm; arc tolerance 0.002 mm = {0.002 * STEPS_PER_MM:g} step)")
    with tempfile.TemporaryDirectory() as tmp:
        for mm in ((0.1, 0.1, 0.0),) if quick else ((0.1, 0.1, 0.0), (0.3, 0.25, 0.0)):
            for label, gcode, kind in jobs:
                runs: dict[bool, Ran] = {}
                for compensate in (True, False):
                    runs[compensate] = ran = run_job(Path(tmp), f"{kind}-{compensate}", gcode, mm, compensate)
                    assert ran.ended_by == "done", ran.ended_by
                lines = (3, len(gcode.splitlines()) - 1)  # after the G0 to the start, before the rapid home
                errors = {c: circle_error(r, 20, *lines) if kind == "circle"
                          else path_error(r, pocket_path(20, 6, 1.5), *lines) for c, r in runs.items()}
                with_, without = runs[True], runs[False]
                same = np.array_equal(with_.rows[:, :3].astype(np.int64),
                                      predict(with_.sent.segments.segments(), axis_count=3).steps)
                ticks = (with_.sent.segments.ticks, without.sent.segments.ticks)
                kinds = sorted({t.kind for t in with_.sent.compensated.takeups})
                print(f"  {label}, backlash X {mm[0]:g} Y {mm[1]:g} mm ({mm[0] * STEPS_PER_MM:g}, "
                      f"{mm[1] * STEPS_PER_MM:g} steps): {len(with_.sent.compensated.takeups)} take-ups "
                      f"({', '.join(kinds)})")
                steppers = "" if kind != "circle" else (
                    f" (away from the circle's two ends, 0.1 s each: {circle_error(with_, 20, *lines, TICK_HZ // 10):.2f})"
                    f"; the steppers alone, no backlash: {stepper_circle_error(with_.plan, 20, *lines):.2f}")
                print(f"    path error: {errors[True]:.2f} steps with compensation, {errors[False]:.2f} without"
                      + steppers)
                print(f"    job time: {ticks[0] / TICK_HZ:.4f} s with, {ticks[1] / TICK_HZ:.4f} s without "
                      f"({100 * (ticks[0] / ticks[1] - 1):+.3f} %)")
                accel = takeup_accel(with_, SMOOTHING)
                quantum = 2 / SMOOTHING**2 * TICK_HZ**2 / STEPS_PER_MM
                print(f"    trace = the stream's predicted steps, take-ups included: {same}")
                for axis, (exact, seen) in sorted(accel.items()):
                    limit = with_.config.axes[axis].max_accel
                    print(f"    {AXES[axis]} acceleration during take-ups: {exact:.1f} mm/s² (stream states), "
                          f"{seen:.1f} ± {quantum:.0f} (trace, {1000 * SMOOTHING // TICK_HZ} ms second "
                          f"differences); limit {limit:g}")


def sawtooth(teeth: int, pitch: float, height: float, feed: float) -> tuple[str, np.ndarray]:
    """Teeth along X whose Y reverses at every tip, at a corner the path keeps speed through without backlash
    (53° turns): its G-code and corners (mm)."""
    corners = np.array([(0.0, 0.0)] + [(pitch * (k + 1), height if k % 2 == 0 else 0.0) for k in range(teeth)])
    body = "".join(f"G1 X{x:.3f} Y{y:.3f}\n" for x, y in corners[1:])
    return f"G21 G90\nG1 X0 Y0 F{feed * 60:g}\n" + body + "G0 X0 Y0\n", corners


def zigzag_figures(quick: bool) -> None:
    passes, length, step, feed = (6 if quick else 20), 20.0, 0.5, 20.0
    teeth, pitch, height = (6 if quick else 20), 10.0, 5.0
    jobs = [(f"zigzag: {passes} passes of {length:g} mm along X, {step:g} mm further along Y each, {feed:g} mm/s "
             "(X reverses sharply at every tip, backlash on X)", zigzag_gcode(passes, length, step, feed),
             zigzag_path(passes, length, step), 0, passes + 2),
            (f"sawtooth: {teeth} teeth {pitch:g} mm long, {height:g} mm high, {feed:g} mm/s (Y reverses sharply at "
             "every tip, backlash on Y)", *sawtooth(teeth, pitch, height, feed), 1, teeth + 2)]
    with tempfile.TemporaryDirectory() as tmp:
        for label, gcode, corners, axis, last_line in jobs:
            print(label + "; path error in steps from the simulated carriage")
            lines = (3, last_line)  # after the G1 to the start, before the rapid home
            without = run_job(Path(tmp), "none", gcode, (0.0, 0.0, 0.0), True)
            assert without.ended_by == "done", without.ended_by
            print(f"  no backlash: job time {without.sent.segments.ticks / TICK_HZ:.4f} s, path error "
                  f"{path_error(without, corners, *lines):.2f} steps (the steppers alone)")
            for mm in (1 / STEPS_PER_MM, 0.05, 0.2):
                backlash = tuple(mm if a == axis else 0.0 for a in range(3))
                ran = run_job(Path(tmp), f"b-{mm}", gcode, backlash, True)
                assert ran.ended_by == "done", ran.ended_by
                ticks = (ran.sent.segments.ticks, without.sent.segments.ticks)
                same = np.array_equal(ran.rows[:, :3].astype(np.int64),
                                      predict(ran.sent.segments.segments(), axis_count=3).steps)
                kinds = sorted({t.kind for t in ran.sent.compensated.takeups})
                accel = takeup_accel(ran, SMOOTHING).get(axis, (0.0, 0.0))[0]
                print(f"  backlash {mm:g} mm ({mm * STEPS_PER_MM:g} steps): job time {ticks[0] / TICK_HZ:.4f} s "
                      f"({100 * (ticks[0] / ticks[1] - 1):+.3f} %), {len(ran.sent.compensated.takeups)} take-ups "
                      f"({', '.join(kinds)}); path error {path_error(ran, corners, *lines):.2f} steps, behind the "
                      f"plan {plan_lag(ran):.2f} steps; {'XYZ'[axis]} acceleration during take-ups {accel:.1f} "
                      f"mm/s²; trace = prediction: {same}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--values", type=int, default=20, help="backlash values per axis (default 20)")
    parser.add_argument("--tries", type=int, default=5, help="tries per measurement (default 5)")
    parser.add_argument("--quick", action="store_true", help="3 values, 2 tries, one backlash for the jobs")
    parser.add_argument("--only", choices=("jobs", "zigzag", "measurement"), help="one part")
    args = parser.parse_args()
    values, tries = (3, 2) if args.quick else (args.values, args.tries)
    if args.only in (None, "jobs"):
        jobs_figures(args.quick)
    if args.only in (None, "zigzag"):
        zigzag_figures(args.quick)
    if args.only in (None, "measurement"):
        measurement(values, tries)
    return 0


if __name__ == "__main__":
    sys.exit(main())
