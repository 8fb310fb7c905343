"""GRBL 1.1's byte stream: lines ended by CR or LF (each one: a sender sends LF alone), and realtime
commands (one byte each) taken out of the stream wherever they arrive, even in the middle of a line;
and the text of GRBL's answers."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

BANNER = "Grbl 1.1h ['$' for help]"
VERSION = "[VER:1.1h.quadstep:]"
OPTIONS = (
    "[OPT:V,15,128]"  # variable spindle; 15 planner blocks, 128-byte receive buffer as GRBL has
)
RX_BUFFER = 128
MAX_LINE = 256  # characters a line may have (GRBL's error 11 beyond)

STATUS = 0x3F  # '?'
FEED_HOLD = 0x21  # '!'
CYCLE_START = 0x7E  # '~'
SOFT_RESET = 0x18
JOG_CANCEL = 0x85
SIMPLE_REALTIME = frozenset({STATUS, FEED_HOLD, CYCLE_START, SOFT_RESET})


def is_extended_realtime(byte: int) -> bool:
    """GRBL's realtime commands above 0x7F (safety door, overrides, coolant toggles, jog cancel)."""
    return byte >= 0x80


@dataclass(frozen=True)
class Realtime:
    byte: int


@dataclass(frozen=True)
class Line:
    text: str
    overflow: bool = False  # longer than MAX_LINE: answered error 11, never executed


class StreamSplitter:
    """Bytes in, Realtime and Line events out, in the order they complete."""

    def __init__(self) -> None:
        self._line = bytearray()
        self._overflow = False

    def feed(self, data: bytes) -> Iterator[Realtime | Line]:
        for byte in data:
            if byte in SIMPLE_REALTIME or is_extended_realtime(byte):
                yield Realtime(byte)
            elif byte in (
                0x0A,
                0x0D,
            ):  # each ends a line, an empty one too (answered ok, as GRBL does)
                yield Line(self._line.decode("ascii", "replace"), self._overflow)
                self._line.clear()
                self._overflow = False
            elif len(self._line) < MAX_LINE:
                self._line.append(byte)
            else:
                self._overflow = True

    def clear(self) -> None:
        """A soft reset drops the line being received."""
        self._line.clear()
        self._overflow = False


def numbers(values: Sequence[float]) -> str:
    return ",".join(f"{v:.3f}" for v in values)


@dataclass(frozen=True)
class StatusFields:
    state: str  # Idle, Run, Hold:0, Hold:1, Jog, Alarm, Home, Check
    position: tuple[float, ...]  # machine mm (MPos:), or work mm (WPos:) where `work`
    feed: float  # mm/min
    speed: float  # S
    wco: tuple[float, ...] | None = None  # the work offset, in reports that carry it
    accessories: str = ""  # A: with Ov:, S/C spindle CW/CCW, F flood, M mist (those on)
    overrides: tuple[int, int, int] | None = None  # Ov:feed,rapid,spindle % in some reports
    work: bool = False  # $10 bit 0 clear: the position in work coordinates
    buffer: tuple[int, int] | None = None  # Bf:blocks,bytes free ($10 bit 1)
    pins: str = ""  # Pn: the active inputs' letters


def status_report(fields: StatusFields) -> str:
    """The report's fields in GRBL's order."""
    parts = [fields.state, f"{'WPos' if fields.work else 'MPos'}:{numbers(fields.position)}"]
    if fields.buffer is not None:
        parts.append(f"Bf:{fields.buffer[0]},{fields.buffer[1]}")
    parts.append(f"FS:{fields.feed:.0f},{fields.speed:.0f}")
    if fields.pins:
        parts.append(f"Pn:{fields.pins}")
    if fields.wco is not None:
        parts.append(f"WCO:{numbers(fields.wco)}")
    if fields.overrides is not None:
        parts.append(f"Ov:{','.join(str(v) for v in fields.overrides)}")
        if fields.accessories:
            parts.append(f"A:{fields.accessories}")
    return "<" + "|".join(parts) + ">"
