"""`quadstep run JOB`: plan a whole job, check it against the machine, then stream it.

Nothing is sent until the job has been read, checked against the travel and
planned completely, and the firmware's tick rate and axes match the
configuration. Ctrl-C stops the machine at once (STOP) and reports where.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable

import numpy as np
from pydantic import BaseModel
from rich.console import Console
from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn

from ..config import MachineConfig
from ..job import Job, read_program
from ..link import Link
from ..planner.program import JobError
from ..protocol import State, StatusReport
from ..protocol.segment import N_MAX
from ._jobs import add_job_options, format_duration, job_from_args, machine_config, skipped_text
from .options import CliError, add_connection_options, add_json_option, connect


class RunResult(BaseModel):
    """What `quadstep run --json` prints."""

    file: str
    completed: bool
    stopped_at_line: int | None
    segments: int
    planned_duration_s: float
    motion_ticks: int
    positions_steps: list[int]
    positions_mm: list[float]
    planned_steps: list[int]
    exact: bool
    link: dict[str, int]


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("run", help="plan and check a whole job, then stream it to the machine")
    add_job_options(parser)
    add_connection_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def check_firmware(link: Link, config: MachineConfig, config_name: str) -> None:
    """Refuse a firmware whose tick rate, axes or segment length differ from what the plan assumes."""
    ident = link.identity
    assert ident is not None
    if ident.tick_hz != config.tick_hz:
        raise CliError(
            f"{config_name}: tick_hz = {config.tick_hz}, but the firmware ticks at {ident.tick_hz} Hz "
            f"(identify); set tick_hz = {ident.tick_hz} in the configuration"
        )
    if ident.axis_count < len(config.axes):
        raise CliError(f"{config_name}: {len(config.axes)} axes configured, the firmware drives {ident.axis_count}")
    if ident.n_max < N_MAX:
        raise CliError(f"the firmware's n_max is {ident.n_max}; quadstep plans segments of up to {N_MAX} ticks")


class Streamer:
    """Sends a planned job in order, pausing where it asks for the operator, reporting progress."""

    def __init__(self, link: Link, job: Job, on_progress: Callable[[int], None], ask: Callable[[int], bool]) -> None:
        self.link = link
        self.job = job
        self.on_progress = on_progress
        self.ask = ask  # called at each pause with its line; False stops the job there
        self.base = link.segments_done

    def done(self) -> int:
        return self.link.segments_done - self.base

    def run(self) -> StatusReport:
        plan = self.job.plan
        pauses = dict(plan.pauses)
        last_report = 0.0
        for i in range(len(plan)):
            if i in pauses and not self._pause(pauses[i]):
                return self.link.status()
            self.link.send(plan.segments.segment(i))
            now = time.monotonic()
            if now - last_report > 0.1:
                self.on_progress(self.done())
                last_report = now
        if len(plan) in pauses:
            self._pause(pauses[len(plan)])
        self.link.drain()
        while self.link.status().state == State.RUNNING:
            self.on_progress(self.done())
            time.sleep(0.1)
        final = self.link.wait_idle(timeout=10)
        self.on_progress(self.done())
        return final

    def _pause(self, line: int) -> bool:
        self.link.wait_idle()
        self.on_progress(self.done())
        return self.ask(line)


def ask_operator(label: str, line: int) -> bool:
    """Wait for Enter on stdin; False when stdin is closed."""
    where = f"line {line} (M0)" if label == "line" else f"{label} {line}"
    print(f"paused at {where}: press Enter to continue, Ctrl-C to stop", file=sys.stderr, flush=True)
    return sys.stdin.readline() != ""


def positions_text(config: MachineConfig, steps: list[int]) -> str:
    return "  ".join(
        f"{axis.name} {axis.to_mm(s):.3f} mm ({s} steps)" for axis, s in zip(config.axes, steps)
    )


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    config_name = str(args.config or "quadstep.toml")
    try:  # syntax errors before touching the machine; the plan needs its position
        read_program(args.job, config, (0,) * len(config.axes), args.skip_unsupported)
    except JobError as exc:
        raise CliError(str(exc)) from None
    with connect(args, tick_hz=config.tick_hz, axes=len(config.axes)) as link:
        check_firmware(link, config, config_name)
        status = link.status()
        if status.state != State.IDLE or status.queue_fill:
            raise CliError(f"the firmware is {status.state.name}, not IDLE; nothing was sent")
        job = job_from_args(args, config, tuple(status.position[: len(config.axes)]))
        if not args.json:
            skipped = skipped_text(job)
            if skipped:
                print(skipped)
            print(
                f"{job.path}: {job.source_size}, {job.plan.moves} moves, {len(job.plan)} segments, "
                f"{format_duration(job.plan.duration_s)} planned; every target inside the travel",
                flush=True,
            )
        return stream(args, link, job, config, status)


def stream(args: argparse.Namespace, link: Link, job: Job, config: MachineConfig, start: StatusReport) -> int:
    plan = job.plan
    ends = np.cumsum(plan.segments.numpy()["n"], dtype=np.int64)
    lines = plan.segments.numpy()["line"]
    total_ticks = int(ends[-1]) if len(ends) else 0
    console = Console(stderr=True)
    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[left]} left"),
        console=console,
        disable=args.json or not console.is_terminal,
    )
    task = progress.add_task(
        f"{job.label} 0/{job.program.lines}", total=max(total_ticks, 1), left=format_duration(plan.duration_s)
    )

    def show(done: int) -> None:
        ticks = int(ends[done - 1]) if done else 0
        line = int(lines[min(done, len(lines) - 1)]) if len(lines) else 0
        left = format_duration((total_ticks - ticks) / config.tick_hz)
        progress.update(task, completed=ticks, description=f"{job.label} {line}/{job.program.lines}", left=left)

    def ask(line: int) -> bool:
        progress.stop()  # the prompt must not be drawn over
        try:
            return ask_operator(job.label, line)
        finally:
            progress.start()

    streamer = Streamer(link, job, show, ask)
    interrupted = False
    stopped_line: int | None = None
    with progress:
        try:
            final = streamer.run()
        except KeyboardInterrupt:
            final = link.stop()
            interrupted = True
    completed = not interrupted and final.segments_done - start.segments_done >= len(plan)
    if not completed:
        done = final.segments_done - start.segments_done
        stopped_line = int(lines[min(done, len(lines) - 1)]) if len(lines) else None
    positions = list(final.position[: len(config.axes)])
    exact = completed and tuple(positions) == plan.end
    result = RunResult(
        file=str(job.path),
        completed=completed,
        stopped_at_line=stopped_line,
        segments=len(plan),
        planned_duration_s=plan.duration_s,
        motion_ticks=final.motion_ticks - start.motion_ticks,
        positions_steps=positions,
        positions_mm=[axis.to_mm(s) for axis, s in zip(config.axes, positions)],
        planned_steps=list(plan.end),
        exact=exact,
        link=link.stats.as_dict(),
    )
    if args.json:
        print(result.model_dump_json())
    else:
        if completed:
            print(
                f"done: {job.source_size}, {len(plan)} segments, "
                f"{format_duration(result.motion_ticks / config.tick_hz)} of motion"
            )
        else:
            print(f"stopped at {job.label} {stopped_line}")
        print(f"position: {positions_text(config, positions)}")
        if completed:
            print("every axis is exactly where the job put it" if exact else
                  f"position differs from the plan: {positions_text(config, list(plan.end))}")
    if interrupted:
        return 130
    return 0 if exact else 1
