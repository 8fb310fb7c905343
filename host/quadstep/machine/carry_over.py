"""What a machine opened anew keeps of the state file: all of it for the same boot of the board,
only the work offsets (relative to machine zero, which homing finds again) for a board reset
since."""

from __future__ import annotations

from dataclasses import dataclass

from ..backlash.band import Band
from ..config import MachineConfig
from ..coordinates import WorkCoordinates
from ..protocol import IdentifyReply, StatusReport
from .board_identity import was_reset
from .state import StateFile

RESET_NOTICE = "the board was reset since the last command: its position is lost; home it"
MOVED_NOTICE = (
    "the board's step counts changed since its state was kept (moved by a command that "
    "keeps none, or one that ended abruptly): where each carriage sits in its backlash "
    "is known again once it moves"
)


@dataclass(frozen=True)
class CarriedOver:
    coordinates: WorkCoordinates
    band: Band
    homed: bool
    position_lost: bool
    notice: str | None  # what the user is told at connect (None: nothing lost)


def carry_over(
    kept: StateFile,
    config: MachineConfig,
    identity: IdentifyReply,
    status: StatusReport,
    new_board: bool = False,
) -> CarriedOver:
    """What of `kept` holds for the board that reports `identity` and `status` at rest; `new_board`:
    one that cannot be the one the state was written for (an emulator started for this machine)."""
    motor = tuple(status.position[: len(config.axes)])
    fresh = Band.of(config)
    band = kept.band.restore(config, motor) if kept.band is not None else fresh
    if kept.board is None:  # no board recorded (version 1, or no file): the band where counts agree
        return CarriedOver(kept.coordinates, band, False, False, None)
    if new_board or was_reset(kept.board, identity, status):
        lost = kept.homed or kept.position_lost
        notice = None if new_board else RESET_NOTICE
        return CarriedOver(kept.coordinates, fresh, False, lost, notice)
    moved = kept.board.position[: len(motor)] != list(motor)
    notice = MOVED_NOTICE if moved and fresh.active and kept.band is not None else None
    return CarriedOver(kept.coordinates, band, kept.homed, kept.position_lost, notice)
