#!/usr/bin/env python3
"""Fault figures (docs/FAULTS.md): goodput against the byte-fault rate, a soak, a silent board, the host killed
and the queue run dry at full speed, with the real emulator behind the byte-level proxy (tests/helpers/byte_faults.py).

    python3 tests/bench/bench_faults.py [--only goodput,soak,silent,stops] [--runs R] [--moves N]
        [--paced-moves N] [--soak-segments N] [--trials N]      (--only also takes files: the bad-file corpus)

Every fault damages one byte of the line (a bit flipped, the byte dropped, doubled, or a random byte inserted
before it) at rate p per byte, in both directions, at 500,000 baud. Goodput is the rate at which the link gets
segments into a free-running emulator, which takes them as fast as they come. The real-time job runs on the paced
emulator (the board's own time) and is checked tick for tick against the fault-free prediction. Prints figures
only; tests/link/test_faults.py and tests/machine/test_controlled_stops.py hold the pass/fail checks.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from bad_files import corpus, judge  # noqa: E402
from byte_faults import FaultyLine  # noqa: E402
from fault_jobs import engraving  # noqa: E402
from host_helpers import read_trace  # noqa: E402

from quadstep.config import MachineConfig, load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.kernel.engine_model import predict, predict_hold, predict_underrun, segment_steps
from quadstep.job import Job, load_job  # noqa: E402
from quadstep.link import BoardSilent, Link, LinkError  # noqa: E402
from quadstep.machine import Machine  # noqa: E402
from quadstep.machine.units import hold_decels  # noqa: E402
from quadstep.protocol import HoldDone, Segment
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove

ROUTER = REPO / "examples" / "router-uno.toml"
RATES = (0.0, 1e-4, 1e-3, 3e-3, 5e-3, 1e-2, 2e-2)
QUEUE = 14  # the Uno's
FAST = "G21 G90\nG0 X250 Y180\nG0 X0 Y0\n"  # rapids: seconds at full speed


@dataclass
class Run:
    """One job through the faulty line."""

    completed: bool
    exact: bool
    seconds: float
    segments: int
    retransmits: int
    faults: int
    ended: str


def rss_kb() -> int:
    """This process's resident memory now (VmRSS), kB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def write_job(folder: Path, moves: int, size: float) -> Path:
    path = folder / f"engraving-{moves}-{size:g}.gcode"
    path.write_text(engraving(moves, size))
    return path


def through_line(emu: Emulator, p: float, config: MachineConfig, path: Path, seed: int,
                 watch: threading.Event | None = None) -> tuple[Job, Run, dict]:
    """Run the job at `path` through a line damaging bytes at `p`; the emulator's summary after it."""
    with FaultyLine(emu.url, p, seed=seed) as line, Link.open(line.port) as link:
        machine = Machine(link, config)
        job = load_job(path, config, machine.position)
        if watch is not None:
            watch.set()
        start = time.monotonic()
        end = machine.run_job(job.plan).wait()
        seconds = time.monotonic() - start
        retransmits = machine.stats.retransmits
        machine.close()
        faults = line.faults
    summary = emu.stop()
    assert end is not None
    completed = end.ended_by == "done" and summary["segments_done"] == len(job.plan)
    exact = (completed and summary["motion_ticks"] == job.plan.duration_ticks
             and [summary[f"position_{a}"] for a in range(3)] == list(job.plan.end))
    if exact and emu.trace is not None:
        expected = predict(job.plan.segments.segments(), list(job.plan.start), axis_count=3)
        exact = bool(np.array_equal(read_trace(emu.trace), expected.steps))
    ended = end.ended_by if end.error is None else end.error.splitlines()[0][:60]
    return job, Run(completed, exact, seconds, len(job.plan), retransmits, faults, ended), summary


def bench_goodput(config: MachineConfig, runs: int, moves: int, paced_moves: int) -> None:
    """Goodput (free-running) and a real-time job (paced) at every rate."""
    print(f"== goodput against the byte-fault rate: {moves}-move engraving job, free-running emulator "
          f"(queue {QUEUE}, {config.tick_hz} Hz), {runs} runs per rate; 500,000 baud both ways")
    print(f"   and a {paced_moves}-move real-time job on the paced emulator, its step trace against the "
          "fault-free prediction")
    print(f"{'p':>7} | {'faults':>6} {'segments/s':>10} {'of p=0':>6} {'retransmits':>11} {'exact':>5} | "
          f"{'real time: complete, trace = prediction, retransmits':<52}")
    base = None
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        free_job, paced_job = write_job(folder, moves, 100.0), write_job(folder, paced_moves, 10.0)
        for p in RATES:
            free = []
            for run in range(runs):
                emu = Emulator(free=True, axes=3, tick_hz=config.tick_hz, queue=QUEUE,
                               trace=folder / "free.csv").start()
                free.append(through_line(emu, p, config, free_job, seed=100 + run)[1])
            rates = [r.segments / r.seconds for r in free]
            rate = statistics.median(rates)
            base = base or rate
            emu = Emulator(axes=3, tick_hz=config.tick_hz, queue=QUEUE, trace=folder / "paced.csv").start()
            paced = through_line(emu, p, config, paced_job, seed=7)[1]
            print(f"{p:7.0e} | {statistics.median(r.faults for r in free):6.0f} {rate:10.0f} {rate / base:6.0%} "
                  f"{statistics.median(r.retransmits for r in free):11.0f} "
                  f"{sum(r.exact for r in free)}/{runs:<3} | "
                  f"{'yes' if paced.completed else 'NO (' + paced.ended + ')'}, "
                  f"{'yes' if paced.exact else 'no'}, {paced.retransmits} ({paced.faults} faults, "
                  f"{paced.seconds:.1f} s)", flush=True)


def pulses(job: Job) -> list[int]:
    """Steps each axis makes over the job (the emulator's step counters)."""
    total = [0, 0, 0]
    for segment in job.plan.segments.segments():
        for move in segment.axes:
            total[move.axis] += segment_steps(segment.n, move)
    return total


def bench_soak(config: MachineConfig, segments: int) -> None:
    """`segments` segments (or a little more) at p = 1e-3, free-running, with the host's memory sampled."""
    moves = segments  # the engraving job plans a little more than one segment a move
    with tempfile.TemporaryDirectory() as tmp:
        path = write_job(Path(tmp), moves, 100.0)
        emu = Emulator(free=True, axes=3, tick_hz=config.tick_hz, queue=QUEUE).start()
        samples: list[int] = []
        streaming = threading.Event()
        done = threading.Event()

        def sample() -> None:
            streaming.wait()
            while not done.wait(1.0):
                samples.append(rss_kb())

        sampler = threading.Thread(target=sample, daemon=True)
        sampler.start()
        before = rss_kb()
        job, run, summary = through_line(emu, 1e-3, config, path, seed=11, watch=streaming)
        done.set()
        sampler.join()
    exact = run.exact and [summary[f"steps_{a}"] for a in range(3)] == pulses(job)
    quarter = len(samples) // 4
    print(f"== soak: {run.segments:,} segments ({moves:,} moves) through p = 1e-3 both ways, free-running")
    print(f"  {'completed' if run.completed else 'NOT completed: ' + run.ended}; exact (every position, "
          f"motion tick and step count): {'yes' if exact else 'NO'}; {run.seconds:.0f} s, "
          f"{run.segments / run.seconds:.0f} segments/s, {run.faults} faults, {run.retransmits} retransmits")
    print(f"  host RSS: {before / 1024:.1f} MB before planning; streaming: {samples[0] / 1024:.1f} MB at the start, "
          f"{samples[quarter] / 1024:.1f} at a quarter, {samples[-1] / 1024:.1f} at the end "
          f"(max {max(samples) / 1024:.1f})" if samples else "  (no RSS samples)")


CRUISE = Segment(n=N_MAX, axes=(AxisMove(axis=0, direction=1, v0=D // 8, vn=D // 8, r=0),))


def silent_once(tcp: bool, in_flight: bool) -> tuple[float, str]:
    """Seconds from SIGSTOP of the board to BoardSilent, and its message."""
    with Emulator(tick_hz=20000, queue=4, extra_args=("--tcp", "0") if tcp else ()) as emu, \
            Link.open(emu.url) as link:
        for _ in range(4):
            link.send(CRUISE)
        link.drain(timeout=5)
        os.kill(emu.pid, signal.SIGSTOP)
        start = time.monotonic()
        try:
            if in_flight:
                for _ in range(4):
                    link.send(Segment(n=10, axes=()), timeout=10)
            link.wait_idle(timeout=30)
        except BoardSilent as exc:
            return time.monotonic() - start, str(exc)
        finally:
            os.kill(emu.pid, signal.SIGCONT)
    return float("inf"), "not noticed"


def bench_silent(trials: int) -> None:
    print(f"== a board gone silent (the emulator stopped with SIGSTOP), {trials} trials each: time to the error")
    for tcp in (False, True):
        for in_flight in (False, True):
            results = [silent_once(tcp, in_flight) for _ in range(trials)]
            times = sorted(t for t, _ in results)
            where = "TCP" if tcp else "pty"
            state = "frames in flight" if in_flight else "queue full, nothing in flight"
            print(f"  {where}, {state:29}: min {times[0]:.2f} s  median {statistics.median(times):.2f} s  "
                  f"max {times[-1]:.2f} s")
    print(f"  message: {results[-1][1]}")


def fitted_decel(steps: np.ndarray, axis: int) -> float:
    """An axis's deceleration over a stop, steps per tick²: a quadratic fitted to its position against the tick."""
    rows = steps[steps[:, 1] == axis]
    if len(rows) < 3:
        return 0.0
    position = np.cumsum(rows[:, 2])
    curve = np.polyfit(rows[:, 0] - rows[0, 0], position, 2)
    return abs(2.0 * curve[0])


def describe_stop(config: MachineConfig, what: str, stop_steps: np.ndarray, motion_ticks: int, hold_tick: int,
                  exact_trace: bool, reported: list[int], predicted: list[int]) -> None:
    tick2 = config.tick_hz ** 2
    fits = []
    for axis, spec in enumerate(config.axes[:2]):
        decel = fitted_decel(stop_steps, axis) * tick2 / spec.steps_per_mm
        fits.append(f"{spec.name} {decel:.1f} mm/s² (limit {spec.max_accel:g})")
    print(f"  {what}: {len(stop_steps)} steps over {(motion_ticks - hold_tick) / config.tick_hz * 1e3:.0f} ms to rest; "
          f"fitted deceleration {', '.join(fits)}; trace = a hold at the configured decelerations: "
          f"{'yes' if exact_trace else 'NO'}; position reported {reported} "
          f"{'= predicted' if reported == predicted else '!= predicted ' + str(predicted)}")


def bench_stops(config: MachineConfig) -> None:
    print(f"== controlled stops at full speed (router-uno.toml: rapids at 40 mm/s; host_timeout "
          f"{config.host_timeout:g} s)")
    decels = hold_decels(config)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        job_path = folder / "fast.gcode"
        job_path.write_text(FAST)
        plan = load_job(job_path, config, (0, 0, 0)).plan
        segments = list(plan.segments.segments())

        # The host killed: quadstep run, SIGKILL a second into the first rapid; the board's watchdog stops.
        trace, events = folder / "killed.csv", folder / "events.csv"
        with Emulator(axes=3, tick_hz=config.tick_hz, trace=trace, extra_args=("--events", str(events))) as emu:
            cli = subprocess.Popen([sys.executable, "-m", "quadstep.cli", "run", str(job_path), "--config",
                                    str(ROUTER), "--port", emu.url], stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
            assert cli.stdout is not None
            cli.stdout.readline()
            time.sleep(1.0)
            os.kill(cli.pid, signal.SIGKILL)
            cli.wait()
            time.sleep(config.host_timeout + 1.0)
            with Link.open(emu.url) as link:
                status = link.status()
                link.stop()
        hold_tick = next(int(line.split(",")[1]) for line in events.read_text().splitlines()[1:]
                         if line.startswith("hold,"))
        stop = predict_hold(segments, hold_tick, decels, axis_count=3)
        steps = read_trace(trace)
        after = steps[steps[:, 0] > hold_tick]
        moved = predict(segments, axis_count=3).steps
        exact = bool(np.array_equal(steps, np.concatenate([moved[moved[:, 0] <= hold_tick], stop.steps])))
        describe_stop(config, f"host killed (ALARM {status.alarm.name if status.alarm else None})", after,
                      status.motion_ticks, hold_tick, exact, list(status.position[:3]), stop.positions)

        # An underrun: the stream ends a quarter of the way through, at full speed.
        ticks = np.cumsum([s.n for s in segments])
        half = int(np.searchsorted(ticks, ticks[-1] // 4))
        trace = folder / "underrun.csv"
        with Emulator(axes=3, tick_hz=config.tick_hz, trace=trace) as emu, Link.open(emu.url) as link:
            machine = Machine(link, config)
            end = machine.send_segments(segments[:half]).wait()
            done = link.last_report(HoldDone)
            status = link.status()  # at rest after the alarm
        assert end is not None and done is not None
        stop = predict_underrun(segments[:half], decels, axis_count=3)
        steps = read_trace(trace)
        exact = bool(np.array_equal(steps, np.concatenate([predict(segments[:half], axis_count=3).steps,
                                                            stop.steps])))
        alarm = "UNDERRUN" if "UNDERRUN" in (end.error or "") else end.ended_by
        describe_stop(config, f"underrun (the job ended: {alarm})",
                      steps[steps[:, 0] > done.hold_tick], status.motion_ticks, done.hold_tick, exact,
                      list(end.position), stop.positions)


def bench_files() -> None:
    files = corpus()
    verdicts: dict[str, dict[str, int]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for bad in files:
            kind = bad.name.split("-")[0]
            verdict = judge(bad, Path(tmp))[0]
            verdicts.setdefault(kind, {"refused": 0, "accepted": 0, "traceback": 0})[verdict] += 1
    print(f"== bad files (tests/helpers/bad_files.py): {len(files)} configurations and job files")
    for kind, counts in verdicts.items():
        print(f"  {kind:9} {sum(counts.values()):4} files: {counts['refused']} refused, {counts['accepted']} accepted, "
              f"{counts['traceback']} tracebacks")


def scurve_run(config: MachineConfig, p: float, path: Path, seed: int) -> str:
    """One S-curve job in real time through a line damaging bytes at `p`: "exact" (completed on every target),
    "stopped" (ended naming why, with the exact position), or "HANG" (no end within the job's time and more)."""
    emu = Emulator(axes=3, tick_hz=config.tick_hz, queue=QUEUE).start()
    try:
        with FaultyLine(emu.url, p, seed=seed) as line, Link.open(line.port) as link:
            machine = Machine(link, config)
            job = load_job(path, config, machine.position)
            run = machine.run_job(job.plan, job.program)
            end = run.wait(job.plan.duration_s * 20 + 60)
            if end is None:
                return "HANG"
            starved = run.progress.starvations
            machine.close(bring_to_rest=False)
    except LinkError as exc:
        return f"stopped: {str(exc).splitlines()[0][:70]}"
    finally:
        emu.stop()
    if end.ended_by == "done" and tuple(end.position) == job.plan.end:
        return f"exact ({starved} starvation pauses)" if starved else "exact"
    named = (end.error or end.ended_by).splitlines()[0]
    if end.position:
        return f"stopped at {list(end.position)}: {named[:70]}"
    known = named.find("position [")  # a link that gave up names the last position the board reported
    return f"stopped, {named[known:].split(' steps')[0]}: {named[:50]}" if known >= 0 else f"NO POSITION: {named}"


def bench_scurve(config: MachineConfig, runs: int) -> None:
    """An S-curve job in real time through byte faults at 1e-2 … 5e-2: every run exact, or stopped naming why
    with the exact position; never a hang."""
    jerky = config.model_copy(update={"axes": [a.model_copy(update={"max_jerk": 20000.0}) for a in config.axes]})
    print(f"== S-curve job (max_jerk 20000, 150 moves, paced emulator, queue {QUEUE}) through byte faults, "
          f"{runs} runs per rate")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "job.gcode"
        path.write_text(engraving(150, size=10.0))
        for p in (1e-2, 2e-2, 5e-2):
            outcomes = [scurve_run(jerky, p, path, seed=200 + run) for run in range(runs)]
            exact = sum(o.startswith("exact") for o in outcomes)
            hangs = sum(o == "HANG" for o in outcomes)
            print(f"{p:7.0e}: {exact}/{runs} exact, {hangs} hangs; " + "; ".join(sorted(set(outcomes))),
                  flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default="goodput,soak,silent,stops,files,scurve")
    parser.add_argument("--runs", type=int, default=2, help="free-running runs per fault rate")
    parser.add_argument("--moves", type=int, default=1000, help="moves of the free-running goodput job")
    parser.add_argument("--paced-moves", type=int, default=600, help="moves of the real-time job")
    parser.add_argument("--soak-segments", type=int, default=100_000)
    parser.add_argument("--trials", type=int, default=3, help="silent-board trials per case")
    args = parser.parse_args()
    config = load_config(ROUTER)
    parts = args.only.split(",")
    if "goodput" in parts:
        bench_goodput(config, args.runs, args.moves, args.paced_moves)
    if "soak" in parts:
        bench_soak(config, args.soak_segments)
    if "silent" in parts:
        bench_silent(args.trials)
    if "stops" in parts:
        bench_stops(config)
    if "files" in parts:
        bench_files()
    if "scurve" in parts:
        bench_scurve(config, args.runs)


if __name__ == "__main__":
    main()
