"""The running job's journal: what `quadstep run --resume` needs to go on from the exact move where
motion stopped, after a crash or kill of the host, a dropped port, a closed terminal or an alarm
that kept the position.

A job streams in legs: the whole plan at its start, and the rest planned again after a feed hold, a
starvation, a pause where the operator moved the machine, a probe. Each leg's program (what was left
of the job, in machine coordinates), where its plan began, and where each of its moves ends in the
board's count of segments are written (atomically) as the leg begins, with the board's
`segments_done` then. After any stop, the board's `segments_done` names the segment it was running,
so the move it belongs to, and the rest of the job is that move again from where the machine stands,
then everything after it (remainder.py) — the same rest a feed hold plans. The journal is removed
when the job completes.
"""

from __future__ import annotations

import hashlib
import json
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..planner.approach import approach_to, describe, with_approach
from ..planner.program import (
    Dwell,
    Item,
    LinearMove,
    OutputState,
    Pause,
    ProbeMove,
    Program,
    SetOutputs,
)
from ..textfile import read_text, replace_text
from ..validation import validate
from .job_state import JobState
from .remainder import move_item, rest_of

COUNTER = 2**32  # the board's segments_done wraps here


class JournalError(ValueError):
    """A journal that cannot be read or does not fit the job; the message says which and why."""


class _Record(BaseModel):
    model_config = ConfigDict(extra="forbid")
    line: int


class MoveRecord(_Record):
    kind: Literal["move"] = "move"
    target: tuple[float, ...]
    feed: float | None
    accel: float | None = None
    offset: tuple[float, ...] = ()
    system: str = ""
    deviation: float | None = None


class DwellRecord(_Record):
    kind: Literal["dwell"] = "dwell"
    seconds: float


class PauseRecord(_Record):
    kind: Literal["pause"] = "pause"
    tool: int | None = None
    coordinates: WorkCoordinates | None = None


class OutputsRecord(_Record):
    kind: Literal["outputs"] = "outputs"
    spindle: int
    speed: float
    mist: bool
    flood: bool


class ProbeRecord(_Record):
    kind: Literal["probe"] = "probe"
    code: str
    target: tuple[float, ...]
    feed: float


ItemRecord = Annotated[
    MoveRecord | DwellRecord | PauseRecord | OutputsRecord | ProbeRecord,
    Field(discriminator="kind"),
]


def record_of(item: Item) -> ItemRecord:
    if isinstance(item, LinearMove):
        return MoveRecord(
            line=item.line,
            target=item.target,
            feed=item.feed,
            accel=item.accel,
            offset=item.offset,
            system=item.system,
            deviation=item.deviation,
        )
    if isinstance(item, Dwell):
        return DwellRecord(line=item.line, seconds=item.seconds)
    if isinstance(item, Pause):
        return PauseRecord(line=item.line, tool=item.tool, coordinates=item.coordinates)
    if isinstance(item, SetOutputs):
        state = item.state
        return OutputsRecord(
            line=item.line,
            spindle=state.spindle,
            speed=state.speed,
            mist=state.mist,
            flood=state.flood,
        )
    return ProbeRecord(line=item.line, code=item.code, target=item.target, feed=item.feed)


def item_of(record: ItemRecord) -> Item:
    """The program item `record` keeps; a probe's way on (its `resume`) comes from the file read
    again."""
    if isinstance(record, MoveRecord):
        return LinearMove(
            record.line,
            record.target,
            record.feed,
            record.accel,
            record.offset,
            record.system,
            record.deviation,
        )
    if isinstance(record, DwellRecord):
        return Dwell(record.line, record.seconds)
    if isinstance(record, PauseRecord):
        return Pause(record.line, record.tool, record.coordinates)
    if isinstance(record, OutputsRecord):
        return SetOutputs(
            record.line, OutputState(record.spindle, record.speed, record.mist, record.flood)
        )
    return ProbeMove(record.line, record.code, record.target, record.feed)


class JournalLeg(BaseModel):
    """One leg of the job: its program, and where its moves end in the stream the board counts."""

    model_config = ConfigDict(extra="forbid")

    board_done: int  # the board's segments_done as the leg's first segment was sent
    start: tuple[int, ...]  # step position the leg's plan starts from (take-ups excluded)
    move_ends: list[int]  # per move: the stream segments of the leg up to its end
    segments: int  # stream segments in the leg
    percent: int  # the feed override the rest is planned at
    items: list[ItemRecord]
    coordinates: WorkCoordinates | None = None  # the work coordinates the job leaves


class JobIdentity(BaseModel):
    """Which job a journal belongs to: the file as it was read, and how."""

    model_config = ConfigDict(extra="forbid")

    path: str  # absolute
    sha256: str
    label: str  # "line" (G-code) or "move" (move files)
    skip_unsupported: bool = False
    config: str | None = None  # the configuration file's absolute path (None: the default machine)


class JournalFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    version: Literal[1] = 1
    job: JobIdentity
    boot_id: int | None = None  # the board's boot id (another one: it was reset, its position lost)
    state: str = "streaming"  # the job's state at the last write (job_state.JobState values)
    waiting_at: int | None = None  # the line of the pause the job waited at
    leg: JournalLeg


def file_digest(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as source:
        for block in iter(lambda: source.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def journal_path(state_file: Path) -> Path:
    """Where the journal of the machine whose state is kept in `state_file` lives (beside it)."""
    return state_file.with_name(state_file.stem + ".job.json")


class Journal:
    """Writes the journal of one job as it runs (JobRun calls it; every write replaces the file
    whole)."""

    def __init__(self, path: Path, job: JobIdentity, boot_id: int) -> None:
        self.path = path
        self.job = job
        self.boot_id = boot_id
        self._file: JournalFile | None = None

    @property
    def waiting_at(self) -> int | None:
        return self._file.waiting_at if self._file is not None else None

    def check_writable(self) -> None:
        """Refuse, before anything moves, a journal that could not be written (OSError says why)."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        probe = self.path.with_name(f".{self.path.name}.probe")
        probe.write_text("")
        probe.unlink()

    def begin_leg(
        self,
        program: Program,
        start: Sequence[int],
        move_ends: Sequence[int],
        segments: int,
        board_done: int,
        percent: int,
    ) -> None:
        leg = JournalLeg(
            board_done=board_done % COUNTER,
            start=tuple(start),
            move_ends=list(move_ends),
            segments=segments,
            percent=percent,
            items=[record_of(i) for i in program.items],
            coordinates=program.coordinates,
        )
        self._file = JournalFile(job=self.job, boot_id=self.boot_id, leg=leg)
        self._write()

    def replan(self, move_ends: Sequence[int], segments: int, percent: int) -> None:
        """The leg's rest planned again in place (a feed override): the same program and board
        count."""
        if self._file is None:
            return
        leg = self._file.leg.model_copy(
            update={"move_ends": list(move_ends), "segments": segments, "percent": percent}
        )
        self._file = self._file.model_copy(update={"leg": leg})
        self._write()

    def state(self, state: str, waiting_at: int | None) -> None:
        if self._file is None:
            return
        self._file = self._file.model_copy(update={"state": state, "waiting_at": waiting_at})
        self._write()

    def finish(self) -> None:
        """The job completed: nothing to resume."""
        self.path.unlink(missing_ok=True)

    def note(self, state: JobState, line: int | None) -> None:
        """The job went to `state` (waiting at `line`): where it waits is kept (a pause is offered
        again on resume, also when the job was stopped there); a done job leaves nothing to
        resume. RESUMING is entered by whoever says go on (the TUI's event loop, a signal): nothing
        is written then; the job's own thread writes the state that follows."""
        if state is JobState.RESUMING:
            return
        if state is JobState.DONE:
            self.finish()
        elif state.final:
            self.state(state.value, self.waiting_at)
        elif state is JobState.PAUSED or self.waiting_at is not None:
            self.state(state.value, line)

    def _write(self) -> None:
        assert self._file is not None
        replace_text(self.path, self._file.model_dump_json() + "\n")


def read_journal(path: Path) -> JournalFile | None:
    """The journal kept at `path`, None when there is none."""
    if not path.exists():
        return None
    text = read_text(path, JournalError)
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise JournalError(f"{path}: not a journal: {exc}") from None
    return validate(JournalFile, data, str(path), JournalError)


def resume_item(
    journal: JournalFile, program: Program, config: MachineConfig, board_done: int
) -> int:
    """The index in `program` (the leg's) where the rest begins: the pause the job waited at, else
    the move the board was running when it stopped (`board_done`: its segments_done now)."""
    leg = journal.leg
    if journal.waiting_at is not None:
        for index, item in enumerate(program.items):
            if isinstance(item, Pause) and item.line == journal.waiting_at:
                return index
    done = (board_done - leg.board_done) % COUNTER
    if done > leg.segments:
        raise JournalError(
            f"the board counts {done} segments since the job's last leg began, more than the "
            f"{leg.segments} it was sent: it is not the board the job ran on, or it was reset"
        )
    return move_item(program, config, leg.start, bisect_right(leg.move_ends, done))


def leg_program(journal: JournalFile, fresh: Program) -> Program:
    """The leg's program as kept, each probe given its way on from `fresh` (the file read again)."""
    ways = {item.line: item.resume for item in fresh.items if isinstance(item, ProbeMove)}
    items: list[Item] = []
    for record in journal.leg.items:
        item = item_of(record)
        if isinstance(item, ProbeMove):
            item = ProbeMove(item.line, item.code, item.target, item.feed, ways.get(item.line))
        items.append(item)
    return Program(
        items=items,
        lines=fresh.lines,
        end_line=fresh.end_line,
        coordinates=journal.leg.coordinates or fresh.coordinates,
    )


def move_start(
    program: Program, config: MachineConfig, start: Sequence[int], item: int
) -> tuple[int, ...]:
    """Where the move at `program.items[item]` begins (steps): the target of the move before it."""
    before = [i for i in program.items[:item] if isinstance(i, LinearMove)]
    return config.to_steps(before[-1].target) if before else tuple(start)


def stood_on_move(
    config: MachineConfig, begin: Sequence[int], end: Sequence[int], position: Sequence[int]
) -> bool:
    """Whether `position` is where a stop during the move from `begin` to `end` may leave the
    machine: between the two, or past them by no more than each axis brakes from its top speed (a
    hold brakes each axis on its own)."""
    for axis, b, e, p in zip(config.axes, begin, end, position):
        brake = axis.max_speed**2 / (2 * axis.max_accel) * axis.steps_per_mm + 1
        if not min(b, e) - brake <= p <= max(b, e) + brake:
            return False
    return True


def rest_to_resume(
    journal: JournalFile,
    fresh: Program,
    config: MachineConfig,
    board_done: int,
    position: Sequence[int],
    homed: bool = False,
) -> tuple[Program, str | None]:
    """What is left of the job, and what the machine does first (None: nothing but going on). Where
    the machine stands where the stop left it: the move under way again from there, then everything
    after it, the outputs as they were (and the spindle's spin-up wait). Where it was moved since
    (homed after a hard limit, jogged): a safe approach first (Z up, over, the outputs, Z down at
    feed) to where that move began — only on a homed machine; otherwise refused, as a new path to
    the move's target could cut anything."""
    program = leg_program(journal, fresh)
    item = resume_item(journal, program, config, board_done)
    begin = move_start(program, config, journal.leg.start, item)
    moves = [i for i in program.items[item:] if isinstance(i, LinearMove)]
    moved = (
        bool(moves)
        and journal.waiting_at is None
        and not stood_on_move(config, begin, config.to_steps(moves[0].target), position)
    )
    if not moved:
        return with_spin_up(rest_of(program, item), config), None
    names = config.axis_names
    if not homed:
        raise JournalError(
            "the machine was moved since the job stopped: it stands at "
            f"{_mm(config, names, position)}, and the move under way began at "
            f"{_mm(config, names, begin)}; home it (quadstep home) and resume to approach that "
            "point safely, or start the file at a line (--from-line N)"
        )
    start = config.to_mm(list(journal.leg.start))
    approach = approach_to(
        program, item, config, config.to_mm(list(position)), start, journal.job.label
    )
    return with_approach(program, approach), describe(approach, config, journal.job.label)


def with_spin_up(program: Program, config: MachineConfig) -> Program:
    """A spindle switched on again (the outputs as they were) gets its spin-up wait before the first
    move."""
    first = program.items[0] if program.items else None
    spinning = (
        isinstance(first, SetOutputs)
        and not config.spindle.laser
        and first.state.spindle != 5
        and config.spindle.power(first.state.speed) > 0
    )
    if not spinning or config.spindle.spin_up_s <= 0 or first is None:
        return program
    return replace(
        program, items=[first, Dwell(first.line, config.spindle.spin_up_s), *program.items[1:]]
    )


def _mm(config: MachineConfig, names: Sequence[str], steps: Sequence[int]) -> str:
    return " ".join(f"{n} {mm:.3f}" for n, mm in zip(names, config.to_mm(list(steps))))
