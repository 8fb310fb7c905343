"""Options and loading shared by the job commands (run, check, plot)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..config import ConfigError, MachineConfig, load_config
from ..coordinates import WorkCoordinates
from ..default_machine import DEFAULT_MACHINE_NAME, default_machine
from ..job import Job, load_job
from ..machine import StateError, load_state, state_path
from ..planner.approach import describe
from ..planner.program import JobError

# DEFAULT_CONFIG and config_path live in options.py (connect needs them); commands find them here
from .options import DEFAULT_CONFIG, CliError, config_path  # noqa: F401


def add_job_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "job", type=Path, metavar="JOB", help="G-code file, or a move file (.json, .yaml)"
    )
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help=f"machine configuration (TOML; default ./{DEFAULT_CONFIG})",
    )
    parser.add_argument(
        "--skip-unsupported",
        action="store_true",
        help="skip spindle, coolant and tool words (M3 M4 M5 M6 M7 M8 M9, S, T) instead of "
        "refusing the job",
    )
    parser.add_argument(
        "--from-line",
        type=line_number,
        metavar="N",
        help="start the job at line N (a move file: its move N), in the modes, offsets, feed and "
        "outputs the lines before it leave: Z up to safe_z (default the top of its travel), "
        "over to where line N begins at rapid, the spindle and coolant as there (then "
        "[spindle] spin_up_s), Z down at the feed there",
    )


def line_number(text: str) -> int:
    try:
        number = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"line {text!r} is not a whole number") from None
    if number < 1:
        raise argparse.ArgumentTypeError(f"line {number}: lines are counted from 1")
    return number


def machine_config(args: argparse.Namespace) -> MachineConfig:
    """--config FILE, else ./quadstep.toml, else — with nothing to move, or on the emulator — the
    default machine (said so on stderr); a real board needs a configuration."""
    path = config_path(args)
    if path is None:
        on_board = getattr(args, "emulator", None) is False and getattr(args, "sim", None) is None
        if on_board:
            raise CliError(
                f"no machine configuration: give --config FILE (or put {DEFAULT_CONFIG} in this "
                "directory); examples/router-uno.toml is a commented one to start from"
            )
        print(f"no configuration given: using {DEFAULT_MACHINE_NAME}", file=sys.stderr, flush=True)
        return default_machine()
    try:
        return load_config(path)
    except ConfigError as exc:
        raise CliError(str(exc)) from None


def stored_coordinates(args: argparse.Namespace) -> WorkCoordinates:
    """The work coordinates kept for this configuration (machine/state.py)."""
    try:
        return load_state(state_path(config_path(args)))
    except StateError as exc:
        raise CliError(str(exc)) from None


def job_from_args(
    args: argparse.Namespace,
    config: MachineConfig,
    start: tuple[int, ...] | None = None,
    coordinates: WorkCoordinates | None = None,
) -> Job:
    try:
        return load_job(
            args.job,
            config,
            start,
            args.skip_unsupported,
            coordinates,
            getattr(args, "feed_override", 100),
            getattr(args, "from_line", None),
        )
    except JobError as exc:
        raise CliError(str(exc)) from None


def work_text(system: str, names: tuple[str, ...], work: tuple[float, ...]) -> str:
    return f"work ({system}): " + "  ".join(f"{name} {x:.3f} mm" for name, x in zip(names, work))


def format_duration(seconds: float) -> str:
    minutes, rest = divmod(max(0.0, seconds), 60.0)
    hours, minutes = divmod(int(minutes), 60)
    return f"{hours}:{minutes:02d}:{rest:04.1f}" if hours else f"{minutes}:{rest:04.1f}"


def skipped_text(job: Job) -> str | None:
    skipped = job.program.skipped
    if not skipped:
        return None
    words = ", ".join(f"line {line}: {word}" for line, word in skipped)
    return f"skipped {len(skipped)} unsupported word{'s' if len(skipped) != 1 else ''}: {words}"


def after_end_text(job: Job) -> str | None:
    """A file that goes on after its M2/M30 (several programs joined): what is not run."""
    program = job.program
    if not program.after_end or program.end_line is None:
        return None
    count = program.after_end
    return (
        f"line {program.end_line} ends the program (M2/M30): the {count} line"
        f"{'s' if count != 1 else ''} after it {'are' if count != 1 else 'is'} not run"
    )


def approach_text(job: Job) -> str | None:
    """What a job started at a line does first (--from-line), or None."""
    if job.approach is None:
        return None
    return describe(job.approach, job.plan.config, job.label)
