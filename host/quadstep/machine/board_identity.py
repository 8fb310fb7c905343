"""Which boot of a board the host talks to: the state file's work holds only for the boot it was
written on.

A board's step counts (and so machine zero, and where each carriage sits in its backlash) start anew
at each reset. The firmware makes a boot id at each reset and reports it in IDENTIFY_REPLY, which
tells a reset directly. A state file written before boot ids (version 1) has none: there continuity
decides: a board's motion clock only grows, so a clock below the one the state recorded means the
board was reset since.
"""

from __future__ import annotations

from ..protocol import IdentifyReply, StatusReport
from .state import BoardMark


def boot_id(identity: IdentifyReply) -> int:
    """The board's boot id."""
    return identity.boot_id


def board_mark(identity: IdentifyReply, motion_ticks: int, position: tuple[int, ...]) -> BoardMark:
    """The board as it stands now, to be recorded with the state."""
    return BoardMark(boot_id=boot_id(identity), motion_ticks=motion_ticks, position=list(position))


def was_reset(mark: BoardMark, identity: IdentifyReply, status: StatusReport) -> bool:
    """Whether the board was reset since `mark` was recorded."""
    if mark.boot_id is not None:
        return boot_id(identity) != mark.boot_id
    return status.motion_ticks < mark.motion_ticks
