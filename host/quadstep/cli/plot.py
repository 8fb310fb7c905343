"""`quadstep plot JOB -o FILE.png`: planned speed and acceleration per axis over time, and the
path."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from ..backlash.compensate import TakeUp
from ..machine.takeups import TakeUps
from ..planner.timeline import Timeline, timeline
from ..toolpath import Toolpath, toolpath
from ._jobs import add_job_options, job_from_args, machine_config
from .options import CliError


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "plot", help="plot a job's planned speed, acceleration and path to a PNG"
    )
    add_job_options(parser)
    parser.add_argument(
        "-o", "--output", type=Path, required=True, metavar="FILE.png", help="image to write"
    )
    parser.set_defaults(handler=run)


def _stairs(t: Timeline, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Speed as straight pieces between boundaries, acceleration as steps."""
    time = np.column_stack([t.start, t.end]).ravel()
    speed = np.column_stack([t.speed0[:, i], t.speed1[:, i]]).ravel()
    accel = (
        np.repeat(t.accel[:, i], 2)
        if t.accel1 is None
        else np.column_stack([t.accel[:, i], t.accel1[:, i]]).ravel()
    )
    return time, speed, time, accel


def draw(
    t: Timeline,
    names: list[str],
    title: str,
    output: Path,
    takeups: list[TakeUp] | None = None,
    tick_hz: int = 1,
    path: Toolpath | None = None,
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12, 8), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(3, 2))
    ax_speed = fig.add_subplot(grid[0, 0])
    ax_accel = fig.add_subplot(grid[1, 0], sharex=ax_speed)
    ax_path = fig.add_subplot(grid[:, 1])
    for i, name in enumerate(names):
        time, speed, _, accel = _stairs(t, i)
        ax_speed.plot(time, speed, label=name, linewidth=1)
        ax_accel.plot(time, accel, label=name, linewidth=1)
    # the backlash's take-ups (at rest: added time, drawn at its start)
    for k, takeup in enumerate(takeups or []):
        begin = takeup.planned / tick_hz
        span = takeup.ticks / tick_hz if takeup.kind != "rest" else 0.0
        for axes in (ax_speed, ax_accel):
            axes.axvspan(
                begin,
                begin + max(span, 1e-3),
                color="tab:red",
                alpha=0.2,
                label="backlash take-up" if k == 0 and axes is ax_speed else None,
            )
    ax_speed.set_ylabel("speed (mm/s)")
    ax_accel.set_ylabel("acceleration (mm/s²)")
    ax_accel.set_xlabel("time (s)")
    ax_speed.legend(loc="upper right")
    ax_speed.grid(True, alpha=0.3)
    ax_accel.grid(True, alpha=0.3)
    if len(names) >= 2 and path is None:
        ax_path.plot(t.position[:, 0], t.position[:, 1], linewidth=0.8)
    if len(names) >= 2:
        styles: tuple[tuple[bool, dict[str, Any]], ...] = (
            (True, {"color": "tab:orange", "linestyle": "--", "label": "rapid (G0)"}),
            (False, {"color": "tab:blue", "linestyle": "-", "label": "cut"}),
        )
        for rapid, style in styles:
            # as written
            pieces = [p for p in (path.pieces if path is not None else ()) if p.rapid == rapid]
            xs = [v for p in pieces for v in (p.start[0], p.end[0], np.nan)]
            ys = [v for p in pieces for v in (p.start[1], p.end[1], np.nan)]
            if pieces:
                ax_path.plot(xs, ys, linewidth=0.8, **style)
        if path is not None:
            ax_path.legend(loc="upper right")
        ax_path.set_xlabel(f"{names[0]} (mm)")
        ax_path.set_ylabel(f"{names[1]} (mm)")
        ax_path.set_aspect("equal", adjustable="datalim")
    else:
        ax_path.plot(np.concatenate([[0.0], t.end]), t.position[:, 0], linewidth=0.8)
        ax_path.set_xlabel("time (s)")
        ax_path.set_ylabel(f"{names[0]} (mm)")
    ax_path.set_title(
        "path"
        if path is None or len(names) < 2
        else f"path: {path.cuts} cuts, {path.rapids} rapids"
    )
    ax_path.grid(True, alpha=0.3)
    fig.suptitle(title)
    fig.savefig(output, dpi=100)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    job = job_from_args(args, config)
    if len(job.plan) == 0:
        raise CliError(f"{args.job}: the job has no motion to plot")
    try:
        # the take-ups the machine would add, from the configured backlash
        takeups = TakeUps(config).compensate(job.plan.segments, job.plan.pauses).takeups
        draw(
            timeline(job.plan),
            list(config.axis_names),
            f"{args.job.name}: planned motion",
            args.output,
            takeups,
            config.tick_hz,
            toolpath(job.program, config.to_mm(job.plan.start)),
        )
    except OSError as exc:
        raise CliError(f"cannot write {args.output}: {exc.strerror}") from None
    print(
        f"wrote {args.output}" + (f" ({len(takeups)} backlash take-ups shaded)" if takeups else "")
    )
    return 0
