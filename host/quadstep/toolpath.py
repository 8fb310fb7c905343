"""A job's path as it was written: straight pieces from one target to the next, each a rapid (G0, no
feed) or a cut, and its bounding box in machine and in work coordinates. The TUI draws it, `quadstep
plot` draws it, `quadstep check` prints its box; nothing here plans or talks to a machine."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from .planner.program import LinearMove, Program


@dataclass(frozen=True)
class Piece:
    start: tuple[float, ...]  # machine mm, every configured axis
    end: tuple[float, ...]
    rapid: bool


@dataclass(frozen=True)
class Box:
    low: tuple[float, ...]
    high: tuple[float, ...]


@dataclass(frozen=True)
class Toolpath:
    pieces: tuple[Piece, ...]
    machine_box: Box | None  # None: the job has no move
    # the targets as their lines wrote them (each in the system it was written in)
    work_box: Box | None

    @property
    def rapids(self) -> int:
        return sum(p.rapid for p in self.pieces)

    @property
    def cuts(self) -> int:
        return len(self.pieces) - self.rapids


def _box(points: Sequence[Sequence[float]]) -> Box | None:
    if not points:
        return None
    return Box(tuple(map(min, zip(*points))), tuple(map(max, zip(*points))))


def toolpath(program: Program, start_mm: Sequence[float]) -> Toolpath:
    """The pieces of `program` from machine position `start_mm`; moves that go nowhere are left
    out."""
    pieces: list[Piece] = []
    work: list[tuple[float, ...]] = []
    here = tuple(float(x) for x in start_mm)
    for item in program.items:
        if not isinstance(item, LinearMove):
            continue
        target = tuple(item.target)
        if target != here:
            pieces.append(Piece(here, target, item.feed is None))
            work.append(tuple(item.work(i) for i in range(len(target))))
        here = target
    machine = [pieces[0].start, *(p.end for p in pieces)] if pieces else []
    return Toolpath(tuple(pieces), _box(machine), _box(work))
