"""A whole job: read (G-code or move file), checked against the travel, and planned.

Nothing here talks to a machine: `load_job` either returns a complete plan or
raises JobError, so a job with any problem never moves anything.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pydantic import BaseModel

from .config import MachineConfig
from .coordinates import WorkCoordinates
from .gcode import parse_gcode
from .movefile import move_program, read_move_file
from .planner.approach import Approach, approach_to, item_at_line, with_approach
from .planner.feed_override import scale_feeds
from .planner.plan import Plan, plan_program
from .planner.program import JobError, Program
from .planner.segments import SegmentArrays
from .protocol.codec import encode
from .protocol.cubic_run_size import cubic_wire_bytes
from .protocol.frame_choice import AVR_FRAMES, FrameChoice
from .protocol.frames import next_frame, run_limit
from .protocol.messages import queue_slots
from .protocol.segment_run import RunChain
from .protocol.segment_run_size import quadratic_wire_bytes
from .textfile import read_text

MOVE_FILE_SUFFIXES = (".json", ".yaml", ".yml")


def is_move_file(path: Path) -> bool:
    return path.suffix.lower() in MOVE_FILE_SUFFIXES


# Segments a frame for an Uno: its queue of 14 slots, half of it in one frame (machine/motion.py).
UNO_RUN_LIMIT = run_limit(14)


class AxisSummary(BaseModel):
    name: str
    peak_speed: float  # mm/s
    start_mm: float  # machine coordinates
    end_mm: float
    end_steps: int
    # work coordinates: the start's in the system the job starts in, the end's in the one it ends in
    start_work_mm: float
    end_work_mm: float


class SkippedWord(BaseModel):
    line: int
    word: str


class JobSummary(BaseModel):
    """What `quadstep check` reports, also as JSON."""

    file: str
    lines: int
    moves: int
    segments: int
    distance_mm: float
    duration_s: float
    wire_bytes: int
    pauses: list[int]  # lines of M0 / pause entries
    work_system: str  # the work coordinate system the job ends in (G54 … G59)
    axes: list[AxisSummary]
    skipped: list[SkippedWord]


@dataclass
class Job:
    path: Path
    program: Program
    plan: Plan
    coordinates: WorkCoordinates  # the work coordinates the job starts with
    # % of every programmed feed the plan has (the program keeps them as written)
    feed_override: int = 100
    approach: Approach | None = None  # started at a line (--from-line): how it gets there

    @property
    def end_coordinates(self) -> WorkCoordinates:
        """The work coordinates as the job leaves them (G10, G92, G54…G59 in it; M2/M30)."""
        return self.program.coordinates or self.coordinates

    @property
    def label(self) -> str:
        """What a source position is called in messages: G-code lines, move-file moves."""
        return "move" if is_move_file(self.path) else "line"

    @property
    def source_size(self) -> str:
        """`39 lines` of G-code, or `8 entries` of a move file."""
        count = self.program.lines
        if is_move_file(self.path):
            noun = "entry" if count == 1 else "entries"
        else:
            noun = "line" if count == 1 else "lines"
        return f"{count} {noun}"

    def wire_bytes(self, frames: FrameChoice = AVR_FRAMES) -> int:
        """Bytes the job's segments take on the serial line, framing included, sent as a motion
        sends them to a board that takes `frames` (an Uno's, by default: one SEGMENT a frame,
        CUBIC_SEGMENTS runs), runs of up to an Uno's run limit."""
        segments = self.plan.segments
        quadratic_limit = UNO_RUN_LIMIT if frames.quadratic_runs else 0
        if isinstance(segments, SegmentArrays):  # from the arrays' sizes: no frame is built
            return quadratic_wire_bytes(segments.numpy(), segments.axis_count, quadratic_limit)
        if isinstance(segments.base, list) and not segments.base:  # a jerk-limited plan's
            cubic_limit = UNO_RUN_LIMIT if frames.cubic_runs else 0
            counted = cubic_wire_bytes(segments.extra, segments.axis_count, cubic_limit)
            if counted is not None:
                return counted
        chain = RunChain(segments.axis_count)
        total = index = 0
        while index < len(segments):
            message = next_frame(
                segments,
                index,
                len(segments),
                chain,
                UNO_RUN_LIMIT,
                frames.cubic_runs,
                frames.quadratic_runs,
            )
            total += len(encode(message, 0))
            index += queue_slots(message)
        return total

    def summary(self) -> JobSummary:
        config = self.plan.config
        peaks = self.plan.peak_speeds()
        names = config.axis_names
        start_work = self.coordinates.to_work(names, config.to_mm(self.plan.start))
        end_work = self.end_coordinates.to_work(names, config.to_mm(self.plan.end))
        return JobSummary(
            file=str(self.path),
            lines=self.program.lines,
            moves=self.plan.moves,
            segments=len(self.plan),
            distance_mm=self.plan.distance_mm,
            duration_s=self.plan.duration_s,
            wire_bytes=self.wire_bytes(),
            pauses=[line for _, line in self.plan.pauses],
            work_system=self.end_coordinates.name,
            axes=[
                AxisSummary(
                    name=axis.name,
                    peak_speed=peaks[i],
                    start_mm=axis.to_mm(self.plan.start[i]),
                    end_mm=axis.to_mm(self.plan.end[i]),
                    end_steps=self.plan.end[i],
                    start_work_mm=start_work[i],
                    end_work_mm=end_work[i],
                )
                for i, axis in enumerate(config.axes)
            ],
            skipped=[SkippedWord(line=line, word=word) for line, word in self.program.skipped],
        )


def read_program(
    path: Path,
    config: MachineConfig,
    start_steps: tuple[int, ...],
    skip_unsupported: bool = False,
    coordinates: WorkCoordinates | None = None,
) -> Program:
    """Parse the job file into moves in machine coordinates, starting from `start_steps`, G-code in
    the work coordinates `coordinates` (move files are machine coordinates)."""
    start_mm = config.to_mm(start_steps)
    if is_move_file(path):
        return move_program(read_move_file(path), config.axis_names, start_mm)
    text = read_text(path, JobError)
    try:
        return parse_gcode(
            text, config.axis_names, start_mm, config.arc_tolerance, skip_unsupported, coordinates
        )
    except JobError as exc:
        raise JobError(f"{path}: {exc}") from None


def load_job(
    path: Path,
    config: MachineConfig,
    start_steps: tuple[int, ...] | None = None,
    skip_unsupported: bool = False,
    coordinates: WorkCoordinates | None = None,
    feed_override: int = 100,
    from_line: int | None = None,
) -> Job:
    """Read, check and plan a whole job (its feeds at `feed_override` %), or — `from_line` — the
    job from that line on after an approach from `start_steps` (planner/approach.py); raises
    JobError naming the line (or move) at fault."""
    start = tuple(start_steps) if start_steps is not None else (0,) * len(config.axes)
    coordinates = coordinates if coordinates is not None else WorkCoordinates()
    program = read_program(path, config, start, skip_unsupported, coordinates)
    label = "move" if is_move_file(path) else "line"
    approach = None
    try:
        if from_line is not None:
            first = item_at_line(program, from_line, label)
            approach = approach_to(program, first, config, config.to_mm(start), label=label)
            program = with_approach(program, approach)
        plan = plan_program(scale_feeds(program, feed_override), config, start, label)
    except JobError as exc:
        raise JobError(f"{path}: {exc}") from None
    return Job(
        path=path,
        program=program,
        plan=plan,
        coordinates=coordinates,
        feed_override=feed_override,
        approach=approach,
    )
