"""The powers a motion's queued segments hold in the board's RASTER ring, counted without building
the planner's segments (a motion asks at every report while it waits for room)."""

from __future__ import annotations

from quadstep.kernel.fixed import D
from quadstep.kernel.motion import AxisMove
from quadstep.planner.segments import SegmentArrays
from quadstep.planner.stream import Stream
from quadstep.protocol.raster import Raster, RasterLine, ring_fits
from quadstep.protocol.segment import Segment

CRUISE = AxisMove(axis=0, direction=1, v0=D // 4, vn=D // 4, r=0)


def line(pixels: int) -> RasterLine:
    raster = Raster(n=1000, axes=1, pixel=0, phase=256, pitch=256, power=tuple(range(pixels)))
    return RasterLine(n=1000, axes=(CRUISE,), raster=raster)


def test_the_ring_counts_the_raster_lines_of_a_stream_and_of_a_stream_over_it() -> None:
    plain = Segment(n=1000, axes=(CRUISE,))
    rows = Stream(base=[plain, line(50), line(40), plain], axes=3)
    for k in range(4):
        rows.add_base(k)
    assert [rows.pixels(k) for k in range(4)] == [0, 50, 40, 0]
    taken_up = Stream(base=rows)  # as backlash compensation streams a plan: base items and its own
    taken_up.add_base(0)
    taken_up.add(line(30), line=0)
    taken_up.add_base(2)
    assert [taken_up.pixels(k) for k in range(3)] == [0, 30, 40]
    arrays = SegmentArrays.of([plain, plain], 3)
    assert [arrays.pixels(k) for k in range(2)] == [0, 0]


def test_lines_fit_the_ring_together_up_to_its_size() -> None:
    """The ring of the Mega and the emulator (1,024 powers), and of the Uno's laser build (128)."""
    for ring, fit in ((1024, 21), (128, 2)):  # lines of 48 powers: 1,008 and 96
        full = Stream(base=[line(48)] * (fit + 1), axes=1)
        for k in range(fit + 1):
            full.add_base(k)
        assert ring_fits(full, 0, fit - 1, ring)
        assert not ring_fits(full, 0, fit, ring)
        assert ring_fits(full, 1, fit, ring)
