"""`quadstep grbl` streaming, on the emulator paced at the Uno's tick rate (32 kHz, 14-slot queue):

1. short lines a second: a sender in a process of its own (stream_client.py, as UGS or CNCjs are)
   streams chords a few steps long by character counting, ten times each; the lines a second from
   the first line sent and from the job's start (once the lines received hold what a running job
   keeps back) to rest, and whether the board kept up (no starvation, no stop);
2. a file through the front door against `quadstep run` of it: the wall time from the first motion to
   rest, both ways, and their ratio;
3. jog cancel (0x85) → the first decelerating tick of the HOLD (the emulator's events log), in ms;
4. the CPU time of planning an addition onto an open job, by the job's length (no board);
5. as 2., jerk-limited (max_jerk 20,000 mm/s³ on every axis), 1,200 chords.

Prints figures; asserts no time."""

from __future__ import annotations

import math
import statistics
import subprocess
import sys
import tempfile
import time
from bisect import bisect_left
from dataclasses import replace
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
CLIENT = Path(__file__).with_name("stream_client.py")  # the sender, a process of its own
sys.path.insert(0, str(REPO / "tests" / "helpers"))

from grbl_client import GrblClient, mpos, report_fields  # noqa: E402

from quadstep.cli.grbl import serve_in_thread  # noqa: E402
from quadstep.config import MachineConfig, load_config  # noqa: E402
from quadstep.emulator import Emulator  # noqa: E402
from quadstep.gcode.interpreter import parse_gcode  # noqa: E402
from quadstep.grbl.server import PtyServer  # noqa: E402
from quadstep.link import Link  # noqa: E402
from quadstep.link.transport import favour_the_link  # noqa: E402
from quadstep.machine import JobRun, JobState, Machine  # noqa: E402
from quadstep.machine import job as job_module  # noqa: E402
from quadstep.machine.move_items import MoveItems  # noqa: E402
from quadstep.machine.open_end import settled_moves  # noqa: E402
from quadstep.machine.override import feeds_at, prepare  # noqa: E402
from quadstep.machine.takeups import StreamPlan, TakeUps  # noqa: E402
from quadstep.planner.plan import Plan, plan_program  # noqa: E402

CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SCURVE = CONFIG.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)}
)


def chords(count: int, length_mm: float, feed: float) -> list[str]:
    """A large circle's chords of `length_mm` each (corners too shallow to slow down for)."""
    radius = 20.0
    step = length_mm / radius
    lines = ["G21 G90 G94", f"G0 X{50 + radius:.4f} Y50", f"G1 F{feed:g}"]
    for k in range(1, count + 1):
        angle = k * step
        lines.append(f"X{50 + radius * math.cos(angle):.4f} Y{50 + radius * math.sin(angle):.4f}")
    return lines


class Additions:
    """Each planning of a running job's rest again (an open job's lines added): the job's moves
    then, and the seconds it took."""

    def __init__(self) -> None:
        self.costs: list[tuple[int, float]] = []
        replan = job_module.replan_running

        def timed(*args: Any, **kwargs: Any) -> Any:
            began = time.perf_counter()
            swap = replan(*args, **kwargs)
            plan = args[1]
            moves = plan.base.moves if hasattr(plan, "base") else plan.moves
            self.costs.append((moves, time.perf_counter() - began))
            return swap

        setattr(job_module, "replan_running", timed)  # every job made from now on

    def take(self) -> list[tuple[int, float]]:
        costs, self.costs = self.costs, []
        return costs


def cost_by_length(costs: list[tuple[int, float]]) -> str:
    """The median planning cost of an addition per 1,000 moves of the job."""
    bins: dict[int, list[float]] = {}
    for moves, seconds in costs:
        bins.setdefault(moves // 1000, []).append(seconds)
    return ", ".join(
        f"{k}k–{k + 1}k moves: {1000 * statistics.median(v):.1f} ms (×{len(v)})"
        for k, v in sorted(bins.items())
    )


ADDITIONS = Additions()


class Door:
    def __init__(self, events: Path, config: MachineConfig = CONFIG) -> None:
        favour_the_link()  # as the command line does
        self.config = config
        self.emulator = Emulator(
            tick_hz=config.tick_hz, axes=3, queue=14, extra_args=("--events", str(events))
        ).start()
        self.link = Link.open(self.emulator.url)
        self.machine = Machine(self.link, config)
        self.jobs: list[JobRun] = []
        self.started: list[float] = []  # when each job was given to the machine
        run_job = self.machine.run_job

        def recorded(*args: object, **kwargs: object) -> JobRun:
            job = run_job(*args, **kwargs)  # type: ignore[arg-type]
            self.jobs.append(job)
            self.started.append(time.monotonic())
            return job

        self.machine.run_job = recorded  # type: ignore[method-assign]
        self.pty = PtyServer(self.machine)
        self.thread = serve_in_thread(self.pty)

    def close(self) -> None:
        self.pty.stop()
        self.thread.join(timeout=10)
        self.pty.close()
        self.link.close()
        self.emulator.stop()


def idle(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def streamed(grbl: GrblClient, door: Door, lines: list[str]) -> tuple[float, list[JobRun]]:
    """Wall time from the first line after the rapid to the start to rest, and the jobs it took."""
    elapsed, _, jobs = streamed_timed(grbl, door, lines)
    return elapsed, jobs


def streamed_timed(
    grbl: GrblClient, door: Door, lines: list[str]
) -> tuple[float, float, list[JobRun]]:
    """As streamed(), and the wall time from the first job's start (once the lines received hold
    what a running job keeps back from the board) to rest."""
    grbl.stream_counting(lines[:2])  # the rapid to the start, alone
    grbl.wait_status(idle)
    before = len(door.jobs)
    begun = time.monotonic()
    grbl.stream_counting(lines[2:])
    grbl.wait_status(idle, timeout=600)
    ended = time.monotonic()
    return ended - begun, ended - door.started[before], door.jobs[before:]


def run_whole(door: Door, lines: list[str]) -> float:
    """`quadstep run`'s way: the whole file planned, then run; wall time of the run."""
    config = door.config
    program = parse_gcode(
        "\n".join(lines[2:]) + "\n",
        config.axis_names,
        config.to_mm(door.machine.position),
        config.arc_tolerance,
    )
    plan = plan_program(program, config, door.machine.position)
    begun = time.monotonic()
    job = door.machine.run_job(plan, program)
    end = job.wait(600)
    assert end is not None and end.ended_by == "done", end
    return time.monotonic() - begun


def stops(jobs: list[JobRun]) -> str:
    legs = sum(job.states.history.count(JobState.RESUMING) for job in jobs)
    starved = sum(job.states.starvations for job in jobs)
    return f"{len(jobs)} job(s), {legs} leg(s) from rest, {starved} starvation(s)"


def bench_lines_per_second(door: Door, work: Path, runs: int = 10) -> None:
    print(f"1. short lines through the front door (F2400, 40 mm/s), {runs} runs each:")
    for length in (0.05, 0.025, 0.02):
        lines = chords(3000, length, 2400)
        # the chords alone from rest at their start, as streamed (after the rapid, at rest)
        start = (50 + 20.0, 50.0, 0.0)
        planned = plan_program(
            parse_gcode(
                "\n".join(lines[:1] + lines[2:]) + "\n",
                CONFIG.axis_names,
                start,
                CONFIG.arc_tolerance,
            ),
            CONFIG,
            CONFIG.to_steps(start),
        )
        whole = 3000 / planned.duration_s
        print(f"   chords {length} mm (the whole file planned: {whole:.0f} lines/s):")
        clean = 0
        for _ in range(runs):
            elapsed, running, jobs = streamed_apart(door, work, lines)
            starved = sum(job.states.starvations for job in jobs)
            clean += starved == 0
            print(
                f"      {3000 / elapsed:5.0f} lines/s from the first line, "
                f"{3000 / running:5.0f} from the job's start; {stops(jobs)}"
            )
        print(f"      the board kept up (no stop) in {clean} of {runs} runs")
        print(f"      planning an addition, by job length: {cost_by_length(ADDITIONS.take())}")


def streamed_apart(door: Door, work: Path, lines: list[str]) -> tuple[float, float, list[JobRun]]:
    """As streamed_timed(), the sender in a process of its own (stream_client.py)."""
    path = work / "lines.nc"
    path.write_text("\n".join(lines) + "\n")
    client = subprocess.Popen(
        [sys.executable, str(CLIENT), str(door.pty.path), str(path)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert client.stdin is not None and client.stdout is not None
    try:
        assert client.stdout.readline().strip() == "READY"
        before = len(door.jobs)
        client.stdin.write("\n")
        client.stdin.flush()
        done = client.stdout.readline().split()
        assert done[:1] == ["DONE"], done
    finally:
        client.wait(timeout=60)
    begun, ended = float(done[1]), float(done[2])
    return ended - begun, ended - door.started[before], door.jobs[before:]


def bench_file_ratio(grbl: GrblClient, door: Door, chords: int = 400, runs: int = 3) -> None:
    kind = ", max_jerk 20,000" if door.config.jerk_limited else ""
    section = 5 if kind else 2
    print(f"{section}. a file streamed vs quadstep run ({chords} chords of a spiral, F2400{kind}):")
    ADDITIONS.take()
    lines = ["G21 G90 G94", "G0 X52 Y50", "G1 F2400"]
    for k in range(1, chords + 1):
        angle, radius = k * 0.12, 2.0 + k * 0.02
        lines.append(f"X{50 + radius * math.cos(angle):.3f} Y{50 + radius * math.sin(angle):.3f}")
    ratios = []
    for _ in range(runs):
        front, jobs = streamed(grbl, door, lines)
        grbl.command("G0 X52 Y50")  # the run from the same start
        grbl.wait_status(idle)
        whole = run_whole(door, lines)
        ratios.append(front / whole)
        sent = jobs[-1].plan.duration_s / door.jobs[-1].plan.duration_s
        print(
            f"   front door {front:.3f} s, run {whole:.3f} s: ratio {front / whole:.4f} "
            f"(the last leg's stream against run's: {sent:.4f}); {stops(jobs)}"
        )
    print(f"   median ratio {statistics.median(ratios):.4f}")


def bench_addition_cost(step: int = 32, total: int = 12000) -> None:
    for config in (CONFIG, SCURVE):
        addition_cost(config, step, total)


def addition_cost(config: MachineConfig, step: int, total: int) -> None:
    """An open job's additions without a board: chords given `step` lines at a time, each planned
    onto the job as a running job does (from the stop at its end, with the take-ups), the CPU time
    of each by the job's length then."""
    kind = "S-curve (max_jerk 20,000)" if config.jerk_limited else "constant acceleration"
    print(
        f"4. an addition of {step} lines planned onto an open job, by the job's length (no board), "
        f"{kind}:"
    )
    takeups = TakeUps(config)
    lines = chords(total, 0.02, 2400)
    program = parse_gcode(
        "\n".join(lines) + "\n", config.axis_names, (0.0, 0.0, 0.0), config.arc_tolerance
    )
    head = 2 + step
    job = replace(program, items=program.items[:head])
    plan = plan_program(job, config)
    compensated = takeups.compensate(plan.segments, plan.pauses)
    running = StreamPlan(config, compensated.stream, compensated.pauses, compensated, plan)
    items = MoveItems(config, plan.start)

    def restream(joined: Plan, old: StreamPlan) -> StreamPlan:
        again = takeups.compensate(joined.segments, joined.pauses, old.compensated.band_start)
        return StreamPlan(config, again.stream, again.pauses, again, joined)

    costs: list[tuple[int, float]] = []
    for at in range(head, len(program.items), step):
        job = replace(job, items=[*job.items, *program.items[at : at + step]])
        base = running.base
        move = settled_moves(base)
        first = bisect_left(running.segments.origin, base.move_ends[move - 1]) if move else 0
        began = time.process_time()
        swap = prepare(
            job, running, first, len(running), feeds_at(100), "line", restream, None, items
        )
        costs.append((base.moves, time.process_time() - began))
        assert swap is not None and isinstance(swap.plan, StreamPlan)
        running = swap.plan
    print(f"   {cost_by_length(costs[len(costs) // 20 :])}")
    whole = time.process_time()
    plan_program(program, config)
    whole = time.process_time() - whole
    print(
        f"   the whole file ({running.base.moves} moves) planned once: {whole:.2f} s "
        f"({1000 * whole / running.base.moves:.3f} ms a move)"
    )


def bench_jog_cancel(grbl: GrblClient, events: Path, count: int = 10) -> None:
    print("3. jog cancel (0x85) → first decelerating tick:")
    latencies = []
    if True:
        grbl.command("G90 G0 X50 Y50")
        grbl.wait_status(idle)
        for k in range(count):
            direction = 1 if k % 2 == 0 else -1
            grbl.command(f"$J=G91 X{20 * direction} F1200")
            grbl.wait_status(lambda r: r.startswith("<Jog") and abs(mpos(r)[0] - 50) > 0.5)
            before = holds(events)
            sent = time.monotonic_ns()
            grbl.realtime(0x85)
            grbl.wait_status(idle)
            after = holds(events)
            if len(after) > len(before):
                latencies.append((after[-1] - sent) / 1e6)
            grbl.command("G90 G0 X50")
            grbl.wait_status(idle)
    print(
        f"   {len(latencies)} cancels: median {statistics.median(latencies):.2f} ms, "
        f"max {max(latencies):.2f} ms"
    )


def holds(events: Path) -> list[int]:
    rows = events.read_text().splitlines()[1:] if events.exists() else []
    return [int(row.split(",")[2]) for row in rows if row.startswith("hold,")]


def main() -> None:
    sections = sys.argv[1:] or ["1", "2", "3", "4", "5"]
    if "4" in sections:
        bench_addition_cost()
    if "5" in sections:
        with tempfile.TemporaryDirectory() as work:
            door = Door(Path(work) / "events.csv", SCURVE)
            try:
                with GrblClient(str(door.pty.path)) as grbl:
                    grbl.wait_banner()
                    bench_file_ratio(grbl, door, 1200, runs=1)
            finally:
                door.close()
    if "1" in sections:
        with tempfile.TemporaryDirectory() as work:
            door = Door(Path(work) / "events.csv")
            try:
                bench_lines_per_second(door, Path(work))
            finally:
                door.close()
    if not {"2", "3"} & set(sections):
        return
    with tempfile.TemporaryDirectory() as work:
        events = Path(work) / "events.csv"
        door = Door(events)
        try:
            with GrblClient(str(door.pty.path)) as grbl:
                grbl.wait_banner()
                if "2" in sections:
                    bench_file_ratio(grbl, door)
                if "3" in sections:
                    bench_jog_cancel(grbl, events)
        finally:
            door.close()


if __name__ == "__main__":
    main()
