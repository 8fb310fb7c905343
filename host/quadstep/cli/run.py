"""`quadstep run JOB`: plan a whole job, check it against the machine, then stream it.

Nothing is sent until the job has been read, checked against the travel and
planned completely (a large G-code file: checked whole, then planned a part at
a time as it runs; cli/_streamed.py), and the firmware agrees with the
configuration. Ctrl-C
brings the machine to rest (HOLD) and reports the line and the exact
position; exit code 130. A feed hold (SIGUSR1, or the board's feed hold
button) brings it to rest and keeps the rest of the job; Enter (in a
terminal), SIGUSR2 or the cycle start button resumes it. --feed-override
PERCENT (10–200) runs every feed (not the rapids) at that share.
"""

from __future__ import annotations

import argparse
import select
import signal
import sys
from collections.abc import Callable
from typing import TypeVar

from pydantic import BaseModel
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn

from ..config import MachineConfig
from ..default_machine import DEFAULT_MACHINE_NAME
from ..job import Job, read_program
from ..job_scan import GcodeParts, Scan
from ..machine import JobProgress, JobRun, Machine, MachineError, MotionEnd, state_path
from ..machine.file_feed import FileFeed, feed_file
from ..machine.job_legs import base_plan
from ..machine.journal import Journal
from ..machine.resume import job_journal, resume_job
from ..planner.feed_override import MAX_PERCENT, MIN_PERCENT, check_percent
from ..planner.plan import Plan
from ..planner.program import JobError, Pause
from ..protocol import State, StatusReport
from ._jobs import (
    add_job_options,
    after_end_text,
    approach_text,
    config_path,
    format_duration,
    job_from_args,
    machine_config,
    skipped_text,
    work_text,
)
from ._streamed import check_file, checked_text, notes, streams
from .options import CliError, add_connection_options, add_json_option, connect

PROGRESS_INTERVAL = 0.1  # s between progress updates
T = TypeVar("T")


class RunResult(BaseModel):
    """What `quadstep run --json` prints."""

    file: str
    completed: bool
    stopped_at_line: int | None
    segments: int  # what the machine was sent: take-ups, RASTER rows and every leg included
    planned_duration_s: float  # of the plan the machine ran (its rasters as RASTER rows)
    motion_ticks: int
    positions_steps: list[int]
    positions_mm: list[float]  # machine coordinates
    work_system: str
    positions_work_mm: list[float]
    planned_steps: list[int]
    exact: bool
    starvations: int  # times the board ran dry, braked to rest and the job went on
    link: dict[str, int]


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "run", help="plan and check a whole job, then stream it to the machine"
    )
    add_job_options(parser)
    parser.add_argument(
        "--feed-override",
        type=feed_percent,
        default=100,
        metavar="PERCENT",
        help="run every programmed feed (G1, G2, G3; not the rapids) at PERCENT %% of itself, "
        f"{MIN_PERCENT}–{MAX_PERCENT} (each axis still within its max_speed); default 100",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="go on with JOB where it stopped before its end (a crash, a killed host, a dropped "
        "port, Ctrl-C, an alarm that kept the position): the move under way again from "
        "where the machine stands, then the rest",
    )
    add_connection_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def machine_call(function: Callable[..., T], *args: object) -> T:
    """`function(*args)`, a MachineError as the command's error line."""
    try:
        return function(*args)
    except MachineError as exc:
        raise CliError(str(exc)) from None


def feed_percent(text: str) -> int:
    try:
        return check_percent(int(text))
    except ValueError as exc:
        message = (
            str(exc)
            if "outside" in str(exc)
            else f"feed override {text!r} is not a whole number of percent"
        )
        raise argparse.ArgumentTypeError(message) from None


def ask_operator(label: str, line: int, pause: Pause | None) -> bool:
    """Wait for Enter on stdin; False when stdin is closed (nobody can answer)."""
    if pause is not None and pause.tool is not None:
        print(
            f"tool change at line {line}: put in T{pause.tool} (spindle and coolant off), then "
            "press Enter to continue, Ctrl-C to stop",
            file=sys.stderr,
            flush=True,
        )
    else:
        where = f"line {line} (M0)" if label == "line" else f"{label} {line}"
        print(
            f"paused at {where}: press Enter to continue, Ctrl-C to stop",
            file=sys.stderr,
            flush=True,
        )
    if sys.stdin.readline() != "":
        return True
    what = pause.reason if pause is not None else "the pause"
    print(
        f"stopped at {label} {line}: {what} waits for Enter, and stdin is closed (not a terminal); "
        "run the job from a terminal, or give it what to answer on stdin",
        file=sys.stderr,
        flush=True,
    )
    return False


def positions_text(config: MachineConfig, steps: list[int]) -> str:
    return "  ".join(
        f"{axis.name} {axis.to_mm(s):.3f} mm ({s} steps)" for axis, s in zip(config.axes, steps)
    )


def position_lines(machine: Machine) -> list[str]:
    """Where the machine stands: in work coordinates, then in machine coordinates and steps."""
    return [
        work_text(machine.coordinates.name, machine.config.axis_names, machine.work_position),
        f"machine: {positions_text(machine.config, list(machine.position))}",
    ]


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    path = config_path(args)
    config_name = str(path) if path is not None else DEFAULT_MACHINE_NAME
    streamed = streams(args)
    try:  # syntax errors before touching the machine; the plan needs its position
        if not streamed:  # a large file is checked once, from where the machine stands
            read_program(args.job, config, (0,) * len(config.axes), args.skip_unsupported)
    except JobError as exc:
        raise CliError(str(exc)) from None
    with connect(args, config, config_name, state_path(config_path(args))) as machine:
        status = machine.status()
        if streamed and not args.resume:
            if status.state != State.IDLE or status.queue_fill:
                raise CliError(f"the firmware is {status.state.name}, not IDLE; nothing was sent")
            scan = check_file(args, config, machine.position, machine.coordinates)
            if not scan.probes:
                return stream_file(args, machine, scan, status)
        journal = machine_call(job_journal, machine, args.job, args.skip_unsupported)
        if args.resume:
            job, status, said = machine_call(resume_job, machine, args.job)
            print("\n".join(said), flush=True)
        elif status.state != State.IDLE or status.queue_fill:
            raise CliError(f"the firmware is {status.state.name}, not IDLE; nothing was sent")
        else:
            job = job_from_args(args, config, machine.position, machine.coordinates)
        if not args.json:
            for note in (skipped_text(job), after_end_text(job)):
                if note:
                    print(note)
        return stream(args, machine, job, status, journal)


def started_text(job: Job, runs: Plan) -> str:
    """Said as the job starts: the plan the machine runs (`runs`: its laser rasters as RASTER
    rows where the board has them, which take longer than the G-code's moves at one speed a row
    would), checked whole before it."""
    override = f" at feed override {job.feed_override} %" if job.feed_override != 100 else ""
    return (
        f"{job.path}: {job.source_size}, {job.plan.moves} moves, {len(runs)} segments, "
        f"{format_duration(runs.duration_s)} planned{override}; every target inside the travel"
    )


def follow(
    run_: JobRun, label: str, progress: Progress, show: Callable[[JobProgress], None]
) -> tuple[MotionEnd, bool]:
    """Wait for the job in this (the main) thread, so that Ctrl-C lands here and nowhere in the
    link: then HOLD. SIGUSR1 is a feed hold, SIGUSR2 resumes. Returns how the job ended and whether
    Ctrl-C ended it."""
    asked: list[str] = []
    previous = {
        sig: signal.signal(
            sig, lambda number, _: asked.append("hold" if number == signal.SIGUSR1 else "go")
        )
        for sig in (signal.SIGUSR1, signal.SIGUSR2)
    }
    try:
        return _follow(run_, label, progress, show, asked)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _follow(
    run_: JobRun,
    label: str,
    progress: Progress,
    show: Callable[[JobProgress], None],
    asked: list[str],
) -> tuple[MotionEnd, bool]:
    prompted, starvations = False, 0
    try:
        while True:
            end = run_.wait(PROGRESS_INTERVAL)
            now = run_.progress
            show(now)
            if now.starvations > starvations:
                starvations = now.starvations
                print(
                    f"the board ran dry near {label} {now.line} (the computer fell behind): "
                    "braked to rest, starved, going on",
                    file=sys.stderr,
                    flush=True,
                )
            if end is not None:
                return end, False
            while asked:
                if asked.pop(0) == "hold":
                    run_.feed_hold()
                else:
                    run_.resume()
            line = run_.paused_at
            if line is not None and run_.held:
                if not prompted:
                    prompted = True
                    print(
                        f"feed hold at {label} {line}: Enter, SIGUSR2 or cycle start resumes; "
                        "Ctrl-C stops",
                        file=sys.stderr,
                        flush=True,
                    )
                if (
                    sys.stdin.isatty()
                    and select.select([sys.stdin], [], [], 0)[0]
                    and sys.stdin.readline()
                ):
                    run_.resume()
                continue
            prompted = False
            if line is not None:
                progress.stop()  # the prompt must not be drawn over
                try:
                    answered = ask_operator(label, line, run_.pause)
                finally:
                    progress.start()
                if not answered or not run_.resume():
                    return run_.halt("stdin closed"), False
    except KeyboardInterrupt:
        return run_.halt("interrupt"), True


def stream(
    args: argparse.Namespace,
    machine: Machine,
    job: Job,
    start: StatusReport,
    journal: Journal | None = None,
) -> int:
    config, plan = machine.config, job.plan
    # with its take-ups
    run_ = machine.run_job(
        plan, job.program, job.label, job.feed_override, journal, leaves=job.end_coordinates
    )
    if not args.json:
        print(started_text(job, base_plan(run_.plan)), flush=True)
        if job.approach is not None:
            print(approach_text(job), flush=True)
    console = Console(stderr=True)
    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[left]} left"),
        console=console,
        disable=args.json or not console.is_terminal,
    )
    # what the machine runs: its rasters as RASTER lines, its take-ups, its overrides
    total = max(run_.plan.duration_s, 1e-9)
    task = progress.add_task(
        f"{job.label} 0/{job.program.lines}", total=total, left=format_duration(total)
    )

    def show(now: JobProgress) -> None:
        """The job's own progress: the line it runs, the time its plan has left (planned again after
        a stop)."""
        progress.update(
            task,
            completed=max(0.0, total - now.seconds_left),
            left=format_duration(now.seconds_left),
            description=f"{job.label} {now.line}/{job.program.lines}",
        )

    with progress:
        end, interrupted = follow(run_, job.label, progress, show)
    if end.error:
        resume = (
            f"; once the board answers, quadstep run {args.job} --resume goes on" if journal else ""
        )
        raise CliError(end.error + resume)
    final = machine.status()
    done = run_.progress.done
    completed = end.ended_by == "done" and done >= len(run_.plan)
    stopped_line = None if completed else run_.progress.line
    positions = list(machine.position)
    exact = completed and tuple(positions) == plan.end
    result = RunResult(
        file=str(job.path),
        completed=completed,
        stopped_at_line=stopped_line,
        segments=run_.progress.total,
        planned_duration_s=total,
        motion_ticks=final.motion_ticks - start.motion_ticks,
        positions_steps=positions,
        positions_mm=[axis.to_mm(s) for axis, s in zip(config.axes, positions)],
        work_system=machine.coordinates.name,
        positions_work_mm=list(machine.work_position),
        planned_steps=list(plan.end),
        exact=exact,
        starvations=run_.progress.starvations,
        link=machine.stats.as_dict(),
    )
    if args.json:
        print(result.model_dump_json())
    else:
        if completed:
            print(
                f"done: {job.source_size}, {result.segments} segments, "
                f"{format_duration(result.motion_ticks / config.tick_hz)} of motion"
            )
        else:
            how = " (HOLD)" if end.held else ""
            print(f"stopped at {job.label} {stopped_line}{how}")
        print("\n".join(position_lines(machine)))
        if not completed and journal is not None:
            print(f"quadstep run {args.job} --resume goes on from there")
        if completed:
            print(
                "every axis is exactly where the job put it"
                if exact
                else f"position differs from the plan: {positions_text(config, list(plan.end))}"
            )
    if interrupted:
        return 130
    return 0 if exact else 1


def stream_file(args: argparse.Namespace, machine: Machine, scan: Scan, start: StatusReport) -> int:
    """A large file, checked whole (`scan`): planned and sent a part at a time
    (machine/file_feed.py; no journal is kept for --resume)."""
    config = machine.config
    if not args.json:
        print("\n".join([*notes(scan), checked_text(args.job, scan, args.feed_override)]))
    reader = GcodeParts(
        args.job, config, machine.position, args.skip_unsupported, machine.coordinates
    )
    feed = machine_call(feed_file, machine, reader, args.feed_override)
    console = Console(stderr=True)
    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TaskProgressColumn(),
        console=console,
        disable=args.json or not console.is_terminal,
    )
    task = progress.add_task(f"line 0/{scan.lines}", total=max(scan.lines, 1))

    def show(now: JobProgress) -> None:
        progress.update(task, completed=now.line, description=f"line {now.line}/{scan.lines}")

    with progress:
        end, interrupted = follow_file(feed, progress, show)
    feed.stop()
    if end.error or feed.error:
        raise CliError(end.error or feed.error or "")
    return streamed_result(args, machine, feed, end, start, scan, interrupted)


def follow_file(
    feed: FileFeed, progress: Progress, show: Callable[[JobProgress], None]
) -> tuple[MotionEnd, bool]:
    """follow() the file's job, and the job after it where it ran everything it was given before
    the next part was planned."""
    run_: JobRun | None = feed.run
    while True:
        assert run_ is not None
        end, interrupted = follow(run_, "line", progress, show)
        try:
            run_ = None if interrupted or end.ended_by != "done" else feed.next_run(run_)
        except KeyboardInterrupt:  # between two jobs: the next one, if it started, stops too
            feed.stop()
            return feed.run.halt("interrupt"), True
        if run_ is None:
            return end, interrupted


def streamed_result(
    args: argparse.Namespace,
    machine: Machine,
    feed: FileFeed,
    end: MotionEnd,
    start: StatusReport,
    scan: Scan,
    interrupted: bool,
) -> int:
    """What a streamed job did, said as a job planned whole says it."""
    config, run_ = machine.config, feed.run
    final = machine.status()
    now = run_.progress
    completed = end.ended_by == "done" and now.done >= now.total
    if completed:
        machine.adopt_coordinates(scan.coordinates)
    positions = list(machine.position)
    exact = completed and tuple(positions) == scan.end_steps
    ran_s = (final.motion_ticks - start.motion_ticks) / config.tick_hz
    result = RunResult(
        file=str(args.job),
        completed=completed,
        stopped_at_line=None if completed else now.line,
        segments=feed.segments_before + now.total,
        planned_duration_s=ran_s,  # planned a part at a time: the motion it made
        motion_ticks=final.motion_ticks - start.motion_ticks,
        positions_steps=positions,
        positions_mm=[axis.to_mm(s) for axis, s in zip(config.axes, positions)],
        work_system=machine.coordinates.name,
        positions_work_mm=list(machine.work_position),
        planned_steps=list(scan.end_steps),
        exact=exact,
        starvations=now.starvations,
        link=machine.stats.as_dict(),
    )
    if args.json:
        print(result.model_dump_json())
    else:
        if completed:
            duration = format_duration(ran_s)
            segments = feed.segments_before + now.total
            print(f"done: {scan.lines} lines, {segments} segments, {duration} of motion")
        else:
            print(f"stopped at line {now.line}{' (HOLD)' if end.held else ''}")
        print("\n".join(position_lines(machine)))
        if completed:
            print(
                "every axis is exactly where the job put it"
                if exact
                else "position differs from the plan: "
                f"{positions_text(config, list(scan.end_steps))}"
            )
    if interrupted:
        return 130
    return 0 if exact else 1
