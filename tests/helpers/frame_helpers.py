"""Frames as the firmware reads them, and a plan's segments from a list: for the tests of chained frames."""

from __future__ import annotations

from quadstep.protocol import CubicSegment, Segment
from quadstep.protocol.cubic_run import CubicSegments
from quadstep.protocol.framing import check_block
from quadstep.protocol.segment_run import Segments

SEGMENT_MESSAGES = {cls.CODE: cls for cls in (Segment, CubicSegment, Segments, CubicSegments)}


def read_frame(frame: bytes) -> Segment | CubicSegment | Segments | CubicSegments:
    """A frame's message as the firmware parses it, before its content is checked against any chain."""
    body = check_block(frame[:-1])
    assert isinstance(body, bytes)
    cls = SEGMENT_MESSAGES[body[0]]
    raw = cls.layout().unpack(body[2:])
    assert raw is not None
    return cls.from_wire(raw)


class ListSource:
    """A list of segments as a plan gives them, by index (protocol/frames.py's SegmentSource)."""

    def __init__(self, segments: list[Segment | CubicSegment]) -> None:
        self.items = segments

    def segment(self, i: int) -> Segment | CubicSegment:
        return self.items[i]
