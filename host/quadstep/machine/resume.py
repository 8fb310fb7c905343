"""Going on with a job that stopped before its end (the host killed or crashed, the port dropped,
the terminal closed, Ctrl-C, an alarm that kept the position), from the exact move where motion
stopped, as the job's journal (journal.py) and the board's count of segments say: `quadstep run JOB
--resume`, and the TUI's offer on connect."""

from __future__ import annotations

from pathlib import Path

from ..job import Job, is_move_file, read_program
from ..planner.feed_override import scale_feeds
from ..planner.plan import plan_program
from ..planner.program import JobError, LinearMove
from ..protocol import AlarmCode, State, StatusReport
from .errors import MachineError
from .journal import (
    JobIdentity,
    Journal,
    JournalError,
    JournalFile,
    file_digest,
    journal_path,
    read_journal,
    rest_to_resume,
)
from .machine import Machine

# alarms after a controlled stop: the position is exact
KEPT = (
    AlarmCode.HOST_LOST,
    AlarmCode.UNDERRUN,
)


def job_journal(machine: Machine, job: Path, skip_unsupported: bool = False) -> Journal | None:
    """The journal a job of `job` keeps on this machine (None: the machine keeps no state); a
    MachineError before anything moves when it cannot be written."""
    if machine.state_file is None:
        return None
    identity = JobIdentity(
        path=str(job.resolve()),
        sha256=file_digest(job),
        label="move" if is_move_file(job) else "line",
        skip_unsupported=skip_unsupported,
    )
    journal = Journal(journal_path(machine.state_file), identity, machine.identity.boot_id)
    try:
        journal.check_writable()
    except OSError as exc:
        raise MachineError(
            f"{journal.path}: cannot keep the job's journal there ({exc.strerror}); nothing was "
            "sent"
        ) from None
    return journal


def kept_job(machine: Machine) -> JournalFile | None:
    """The job kept for resuming on this machine, if one is."""
    if machine.state_file is None:
        return None
    try:
        return read_journal(journal_path(machine.state_file))
    except JournalError as exc:
        raise MachineError(str(exc)) from None


def kept_journal(machine: Machine, job: Path) -> JournalFile:
    journal = kept_job(machine)
    if journal is None:
        where = (
            journal_path(machine.state_file)
            if machine.state_file is not None
            else "no state folder"
        )
        raise MachineError(f"nothing to resume: no stopped job is kept for this machine ({where})")
    if str(job.resolve()) != journal.job.path:
        raise MachineError(f"the job kept for --resume is {journal.job.path}, not {job}")
    if file_digest(job) != journal.job.sha256:
        raise MachineError(
            f"{job} changed since the job stopped: --resume goes on only with the file as it "
            "ran (--from-line N starts a changed file at a line)"
        )
    return journal


def at_rest_with_position(
    machine: Machine, journal: JournalFile, status: StatusReport, say: list[str]
) -> StatusReport:
    """The board as the stop left it: cleared of an alarm that kept the position (STOP), refused
    where the position was lost (a hard limit, the abort button, a reset)."""
    if journal.boot_id is not None and machine.identity.boot_id != journal.boot_id:
        raise MachineError(
            "the board was reset since the job stopped, and where it stopped was lost with it; "
            "home the machine, then start the file at a line: quadstep run JOB --from-line N"
        )
    if status.state == State.ALARM:
        if status.alarm not in KEPT:
            raise MachineError(
                f"the board is in ALARM {AlarmCode(status.alarm).name}: the position was lost; "
                "home the machine, then start the file at a line (--from-line N)"
            )
        say.append(
            f"the board stopped on ALARM {AlarmCode(status.alarm).name} with its position kept: "
            "clearing it"
        )
        return machine.emergency_stop()  # STOP at rest: the alarm cleared, positions exact
    if status.state != State.IDLE or status.queue_fill:
        raise MachineError(f"the firmware is {status.state.name}, not at rest; nothing was sent")
    return status


def resume_job(machine: Machine, job: Path) -> tuple[Job, StatusReport, list[str]]:
    """The rest of the job kept for `job`, planned from where the machine stands; the board's status
    it starts from and what to tell the user."""
    journal = kept_journal(machine, job)
    say: list[str] = []
    status = at_rest_with_position(machine, journal, machine.status(), say)
    config, leg = machine.config, journal.leg
    try:
        fresh = read_program(
            job, config, leg.start, journal.job.skip_unsupported, machine.coordinates
        )
        rest, approach = rest_to_resume(
            journal, fresh, config, status.segments_done, machine.position, machine.homed
        )
        plan = plan_program(
            scale_feeds(rest, leg.percent), config, machine.position, journal.job.label
        )
    except (JobError, JournalError) as exc:
        raise MachineError(f"cannot resume {job}: {exc}") from None
    if approach is not None:
        say.append(approach)
    first = next((item.line for item in rest.items if isinstance(item, LinearMove)), None)
    where = f"{journal.job.label} {first}" if first is not None else "its end"
    how = "from a safe approach" if approach is not None else "from where the machine stands"
    say.insert(
        len(say) - (approach is not None),
        f"resuming {job} at {where} ({journal.state} when it "
        f"stopped): the move under way again {how}, then the rest",
    )
    coordinates = machine.coordinates.model_copy(deep=True)
    return (
        Job(path=job, program=rest, plan=plan, coordinates=coordinates, feed_override=leg.percent),
        status,
        say,
    )
