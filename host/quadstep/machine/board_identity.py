"""Which boot of a board the host talks to: the state file's work holds only for the boot it was
written on.

A board's step counts (and so machine zero, and where each carriage sits in its backlash) start anew
at each reset. A firmware that reports a boot id (a number it makes at each reset, in IDENTIFY)
tells a reset directly; without one, continuity does: a board's motion clock only grows, so a clock
below the one the state recorded means the board was reset since (a reset board that has since run
longer than the recorded clock goes unnoticed, as does a clock past its 32 bits: 37 hours of motion
at 32 kHz).
"""

from __future__ import annotations

from ..protocol import IdentifyReply, StatusReport
from .state import BoardMark


def boot_id(identity: IdentifyReply) -> int | None:
    """The board's boot id, where its firmware reports one."""
    value = getattr(identity, "boot_id", None)
    return value if isinstance(value, int) else None


def board_mark(identity: IdentifyReply, motion_ticks: int, position: tuple[int, ...]) -> BoardMark:
    """The board as it stands now, to be recorded with the state."""
    return BoardMark(boot_id=boot_id(identity), motion_ticks=motion_ticks, position=list(position))


def was_reset(mark: BoardMark, identity: IdentifyReply, status: StatusReport) -> bool:
    """Whether the board was reset since `mark` was recorded."""
    now = boot_id(identity)
    if now is not None and mark.boot_id is not None:
        return now != mark.boot_id
    return status.motion_ticks < mark.motion_ticks
