"""A G-code file read and checked a part at a time, in bounded memory: the whole-file check a large
job gets before anything moves, and the parts its run is fed from (machine/file_feed.py).

One pass checks what reading and planning the whole file would check before it is planned: every
line's syntax in the modal state and work offsets before it, every arc, every target against the
travel, and the job's duration against the board's tick counter (each move at its top speed: the
bound planning checks first). It keeps totals only — lines, moves, where the job ends — never the
moves. The file is read as `read_text` reads it (the same refusals, lines ended by a newline only).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from .config import MachineConfig
from .coordinates import WorkCoordinates
from .gcode import GcodeInterpreter
from .planner.feed_override import scale_feeds
from .planner.limits import check_duration
from .planner.moves import build_moves
from .planner.program import Item, JobError, ProbeMove, Program
from .textfile import JOB_MAX_BYTES, open_regular

CHUNK_LINES = 250  # lines a part: what one extension of a running job plans at a time
SKIPPED_KEPT = 100  # skipped words kept to be listed; beyond them only counted


def job_lines(path: Path) -> Iterator[str]:
    """The file's lines, one at a time, as `read_text(path).removesuffix("\\n").split("\\n")`
    gives them (a carriage return before each newline removed); JobError as read_text raises it."""
    try:
        file = open_regular(path, JobError, JOB_MAX_BYTES)
    except OSError as exc:
        raise JobError(f"{path}: cannot read: {exc.strerror}") from None
    with file:
        at = 0  # the byte the line begins at
        for raw in file:
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                raise JobError(
                    f"{path}: not a text file ({exc.reason} at byte {at + exc.start})"
                ) from None
            at += len(raw)
            if at > JOB_MAX_BYTES:
                raise JobError(
                    f"{path}: grew past {JOB_MAX_BYTES / 2**20:g} MB while read, larger than the "
                    f"{JOB_MAX_BYTES / 2**20:g} MB such a file may be"
                )
            yield text.removesuffix("\n").removesuffix("\r")


@dataclass
class Part:
    """Items of consecutive lines: the program's lines read up to them, its work coordinates
    after them."""

    items: list[Item]
    lines: int
    coordinates: WorkCoordinates


@dataclass
class GcodeParts:
    """Reads a G-code file a part at a time (`parts()`), keeping what the whole program would
    report besides its items: lines read, the M2/M30 that ends it and the lines after, skipped
    words (the first SKIPPED_KEPT, and how many)."""

    path: Path
    config: MachineConfig
    start_steps: tuple[int, ...]
    skip_unsupported: bool = False
    coordinates: WorkCoordinates | None = None
    chunk_lines: int = CHUNK_LINES
    lines: int = 0
    end_line: int | None = None
    after_end: int = 0
    skipped: list[tuple[int, str]] = field(default_factory=list)
    skipped_count: int = 0

    def parts(self) -> Iterator[Part]:
        config = self.config
        reader = GcodeInterpreter(
            config.axis_names,
            config.to_mm(self.start_steps),
            config.arc_tolerance,
            self.skip_unsupported,
            self.coordinates,
        )
        program = reader.program
        taken = 0
        lines = job_lines(self.path)
        try:
            for number, text in enumerate(lines, start=1):
                going_on = reader.feed_line(text, number)
                self._take_skipped(program)
                if not going_on:
                    self.lines = number
                    self.end_line = number
                    self.after_end = sum(1 for rest in lines if rest.strip(" \t%"))
                    break
                if number - taken >= self.chunk_lines:
                    yield self._part(program, number)
                    taken = number
            else:
                self.lines = program.lines
        except JobError as exc:
            message = str(exc)
            raise JobError(
                message if message.startswith(f"{self.path}: ") else f"{self.path}: {message}"
            ) from None
        yield self._part(program, self.lines)

    def _take_skipped(self, program: Program) -> None:
        if program.skipped:
            room = SKIPPED_KEPT - len(self.skipped)
            self.skipped.extend(program.skipped[:room])
            self.skipped_count += len(program.skipped)
            program.skipped.clear()

    @staticmethod
    def _part(program: Program, lines: int) -> Part:
        items, program.items = program.items, []
        assert program.coordinates is not None
        return Part(items, lines, program.coordinates.model_copy(deep=True))


@dataclass
class Scan:
    """What checking a whole file found: it passed every check (else JobError was raised)."""

    lines: int
    items: int
    moves: int  # moves that make a step
    end_steps: tuple[int, ...]  # where the last move ends (at the probe's target, with one)
    coordinates: WorkCoordinates  # as the job leaves them
    end_line: int | None
    after_end: int
    skipped: list[tuple[int, str]]
    skipped_count: int
    probes: bool  # G38.x: what follows a probe is read again from where it stops


def scan_job(
    path: Path,
    config: MachineConfig,
    start_steps: tuple[int, ...],
    skip_unsupported: bool = False,
    coordinates: WorkCoordinates | None = None,
    feed_override: int = 100,
    label: str = "line",
) -> Scan:
    """Check the whole G-code file from `start_steps` in one pass, in bounded memory; JobError
    naming the file, line, value and limit: as reading and planning it whole would, the first
    syntax error anywhere, else the first target outside the travel, else where the job passes
    the duration limit."""
    reader = GcodeParts(path, config, start_steps, skip_unsupported, coordinates)
    at, items, moves, ticks = start_steps, 0, 0, 0.0
    probes = False
    travel: JobError | None = None  # the first found; the file's syntax is checked to its end
    duration: JobError | None = None
    coords = coordinates if coordinates is not None else WorkCoordinates()
    for part in reader.parts():
        coords = part.coordinates
        items += len(part.items)
        if probes or travel is not None:
            continue  # after a probe its positions depend on where it stops
        probe = next((i for i, item in enumerate(part.items) if isinstance(item, ProbeMove)), None)
        checked = part.items if probe is None else part.items[: probe + 1]
        program = Program(items=checked, lines=part.lines)
        try:
            table = build_moves(scale_feeds(program, feed_override), config, at, label)
        except JobError as exc:
            travel = exc
            continue
        try:
            if duration is None:
                ticks = check_duration(table, config, label, before=ticks)
        except JobError as exc:
            duration = exc
        moves += len(table)
        at = table.target[-1] if len(table) else at
        probes = probe is not None
    if travel is not None or duration is not None:
        raise JobError(f"{path}: {travel or duration}")
    return Scan(
        lines=reader.lines,
        items=items,
        moves=moves,
        end_steps=at,
        coordinates=coords,
        end_line=reader.end_line,
        after_end=reader.after_end,
        skipped=reader.skipped,
        skipped_count=reader.skipped_count,
        probes=probes,
    )
