"""The frame kind a motion sends each kind of segment in: the one the board takes the most
segments a second in, measured on the board's own firmware (simavr, exact cycles), not the one
with the fewest bytes. At 500,000 baud the line carries 1,852 single three-axis SEGMENT frames a
second, more than an AVR board takes in any frame kind: on those boards bytes are rarely the
limit."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

from .constants import Board, Capability
from .messages import IdentifyReply


class FrameChoice(BaseModel):
    model_config = ConfigDict(frozen=True)

    quadratic_runs: bool  # SEGMENTS (several chained records a frame), else one SEGMENT a frame
    cubic_runs: bool  # CUBIC_SEGMENTS, else one CUBIC_SEGMENT a frame


# The AVR boards (Uno, 32 kHz, three axes stepping every tick, speeds changing every segment): one
# SEGMENT a frame is taken faster than SEGMENTS (about 1,390 against 940 segments/s: reading each
# record's varints against the chain costs the main loop more than a frame's framing saves), while
# CUBIC_SEGMENTS is taken a little faster than one CUBIC_SEGMENT a frame (about 727 against 696).
# The Mega runs the same code at the same clock. (The figures are from when the Uno took SEGMENTS:
# its build now leaves the reader out, docs/AVR.md.)
AVR_FRAMES = FrameChoice(quadratic_runs=False, cubic_runs=True)
_BY_BOARD: dict[int, FrameChoice] = {Board.ATMEGA328P: AVR_FRAMES, Board.ATMEGA2560: AVR_FRAMES}
RUN_FRAMES = FrameChoice(quadratic_runs=True, cubic_runs=True)  # the emulator: bytes are the limit
SINGLE_FRAMES = FrameChoice(quadratic_runs=False, cubic_runs=False)  # a board without runs


def frame_choice(identity: IdentifyReply) -> FrameChoice:
    """The frame kinds for this board, within what its firmware takes (its capabilities)."""
    best = _BY_BOARD.get(identity.board, RUN_FRAMES)  # Board is an IntEnum: its values are the keys
    return FrameChoice(
        quadratic_runs=best.quadratic_runs and bool(identity.capabilities & Capability.SEGMENTS),
        cubic_runs=best.cubic_runs and bool(identity.capabilities & Capability.CUBIC_RUNS),
    )
