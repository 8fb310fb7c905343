"""`quadstep run JOB --resume`: go on with a job that stopped before its end (the host killed or crashed, the
port dropped, the terminal closed, Ctrl-C, an alarm that kept the position), from the exact move where motion
stopped, as the job's journal (machine/journal.py) and the board's count of segments say."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..config import MachineConfig
from ..job import Job, read_program
from ..machine import Machine
from ..machine.journal import (
    Journal, JournalError, JournalFile, JobIdentity, file_digest, journal_path, read_journal, rest_to_resume,
)
from ..planner.feed_override import scale_feeds
from ..planner.plan import plan_program
from ..planner.program import JobError, LinearMove
from ..protocol import AlarmCode, State, StatusReport
from .options import CliError

KEPT = (AlarmCode.HOST_LOST, AlarmCode.UNDERRUN)  # alarms after a controlled stop: the position is exact


def job_journal(args: argparse.Namespace, machine: Machine, config_file: Path | None) -> Journal | None:
    """The journal this run keeps (None: the machine keeps no state); refused before anything moves when it
    cannot be written."""
    if machine.state_file is None:
        return None
    identity = JobIdentity(path=str(args.job.resolve()), sha256=file_digest(args.job), label=label_of(args),
                           skip_unsupported=args.skip_unsupported,
                           config=str(config_file.resolve()) if config_file is not None else None)
    journal = Journal(journal_path(machine.state_file), identity, getattr(machine.identity, "boot_id", None))
    try:
        journal.check_writable()
    except OSError as exc:
        raise CliError(f"{journal.path}: cannot keep the job's journal there ({exc.strerror}); nothing was "
                       "sent") from None
    return journal


def label_of(args: argparse.Namespace) -> str:
    return "move" if args.job.suffix.lower() in (".json", ".yaml", ".yml") else "line"


def kept_journal(args: argparse.Namespace, machine: Machine) -> JournalFile:
    if machine.state_file is None:
        raise CliError("--resume needs the machine's state folder (the journal is kept there)")
    path = journal_path(machine.state_file)
    try:
        journal = read_journal(path)
    except JournalError as exc:
        raise CliError(str(exc)) from None
    if journal is None:
        raise CliError(f"nothing to resume: no stopped job is kept for this machine ({path})")
    if str(args.job.resolve()) != journal.job.path:
        raise CliError(f"the job kept for --resume is {journal.job.path}, not {args.job}")
    if file_digest(args.job) != journal.job.sha256:
        raise CliError(f"{args.job} changed since the job stopped: --resume goes on only with the file as it "
                       "ran (--from-line N starts a changed file at a line)")
    return journal


def at_rest_with_position(machine: Machine, journal: JournalFile, status: StatusReport) -> StatusReport:
    """The board as the stop left it: cleared of an alarm that kept the position (STOP), refused where the
    position was lost (a hard limit, the abort button, a reset)."""
    boot = getattr(machine.identity, "boot_id", None)
    if journal.boot_id is not None and boot is not None and boot != journal.boot_id:
        raise CliError("the board was reset since the job stopped, and where it stopped was lost with it; "
                       "home the machine, then start the file at a line: quadstep run JOB --from-line N")
    if status.state == State.ALARM:
        if status.alarm not in KEPT:
            raise CliError(f"the board is in ALARM {AlarmCode(status.alarm).name}: the position was lost; "
                           "home the machine, then start the file at a line (--from-line N)")
        print(f"the board stopped on ALARM {AlarmCode(status.alarm).name} with its position kept: clearing it")
        return machine.emergency_stop()  # STOP at rest: the alarm cleared, positions exact
    if status.state != State.IDLE or status.queue_fill:
        raise CliError(f"the firmware is {status.state.name}, not at rest; nothing was sent")
    return status


def resumed_job(args: argparse.Namespace, machine: Machine, config: MachineConfig,
                status: StatusReport) -> tuple[Job, StatusReport]:
    """The rest of the kept job, planned from where the machine stands."""
    journal = kept_journal(args, machine)
    status = at_rest_with_position(machine, journal, status)
    leg = journal.leg
    try:
        fresh = read_program(args.job, config, leg.start, journal.job.skip_unsupported, machine.coordinates)
        rest = rest_to_resume(journal, fresh, config, status.segments_done, machine.position)
        plan = plan_program(scale_feeds(rest, leg.percent), config, machine.position, journal.job.label)
    except (JobError, JournalError) as exc:
        raise CliError(f"cannot resume {args.job}: {exc}") from None
    first = next((item.line for item in rest.items if isinstance(item, LinearMove)), None)
    where = f"{journal.job.label} {first}" if first is not None else "its end"
    print(f"resuming {args.job} at {where} ({journal.state} when it stopped): the move under way again from "
          "where the machine stands, then the rest")
    coordinates = machine.coordinates.model_copy(deep=True)
    return Job(path=args.job, program=rest, plan=plan, coordinates=coordinates,
               feed_override=leg.percent), status
