"""A stream of segments as sent: planned quadratic segments with some replaced by others (cubic
ones).

The planner's arrays stay as they are; a stream refers to their segments by index and holds only
what is new, so a job of a few hundred thousand segments costs a few bytes per segment here. It
offers what the machine streams from (`n`, `segment(i)`, `axis_count`) and the source line of each
segment.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from ..protocol.cubic import CubicSegment
from ..protocol.raster import raster_pixels
from ..protocol.segment import Segment
from .segments import SegmentArrays


@dataclass
class Stream:
    """Items in order: segment `ref[i]` of `base` (ref ≥ 0), or `extra[−ref[i] − 1]`."""

    base: SegmentArrays | list[Segment | CubicSegment] | Stream
    axes: int = 0  # the axis count, for a base that is a list
    ref: array = field(default_factory=lambda: array("i"))
    extra: list[Segment | CubicSegment] = field(default_factory=list)
    n: array = field(default_factory=lambda: array("I"))
    line: array = field(default_factory=lambda: array("i"))
    # the base segment each item runs (part of)
    origin: array = field(default_factory=lambda: array("i"))

    @property
    def axis_count(self) -> int:
        return self.axes if isinstance(self.base, list) else self.base.axis_count

    def __len__(self) -> int:
        return len(self.ref)

    def add_base(self, index: int) -> None:
        self.ref.append(index)
        self.origin.append(index)
        if isinstance(self.base, (SegmentArrays, Stream)):
            self.n.append(self.base.n[index])
            self.line.append(self.base.line[index])
        else:
            self.n.append(self.base[index].n)
            self.line.append(0)

    def add_bases(self, start: int, stop: int) -> None:
        """Base segments `start` … `stop` − 1, as add_base() of each, at once."""
        if isinstance(self.base, list):
            for index in range(start, stop):
                self.add_base(index)
            return
        indices = np.arange(start, stop, dtype=np.int32).tobytes()
        self.ref.frombytes(indices)
        self.origin.frombytes(indices)
        self.n.frombytes(np.asarray(self.base.n[start:stop], dtype=np.uint32).tobytes())
        self.line.frombytes(np.asarray(self.base.line[start:stop], dtype=np.int32).tobytes())

    def add(self, segment: Segment | CubicSegment, line: int, origin: int = 0) -> None:
        self.ref.append(-len(self.extra) - 1)
        self.origin.append(origin)
        self.extra.append(segment)
        self.n.append(segment.n)
        self.line.append(line)

    def head(self, count: int) -> Stream:
        """A new stream of the first `count` items, over the same base (to go on adding to)."""
        refs = np.frombuffer(self.ref, np.int32)[:count] if count else np.zeros(0, np.int32)
        extras = -int(refs.min()) if refs.size and refs.min() < 0 else 0  # added in order
        return Stream(
            self.base,
            self.axes,
            self.ref[:count],
            self.extra[:extras],
            self.n[:count],
            self.line[:count],
            self.origin[:count],
        )

    def tail(self, first: int) -> Stream:
        """A new stream of the items from `first` on: a planner's own stream (every item its own
        segment, its own origin), counted from there."""
        assert isinstance(self.base, list) and not self.base
        return Stream(
            self.base,
            self.axes,
            array("i", range(-1, -(len(self) - first) - 1, -1)),
            self.extra[first:],
            self.n[first:],
            self.line[first:],
            array("i", range(len(self) - first)),
        )

    def origin_of(self, i: int) -> int:
        """The base segment that item i runs, or part of it (at the end: the number of base
        segments)."""
        return self.origin[i] if i < len(self) else len(self.base)

    def segment(self, i: int) -> Segment | CubicSegment:
        ref = self.ref[i]
        if ref < 0:
            return self.extra[-ref - 1]
        return self.base[ref] if isinstance(self.base, list) else self.base.segment(ref)

    def pixels(self, i: int) -> int:
        """The powers item i carries to the board's RASTER ring (0 for any other segment), without
        building a segment of the planner's arrays."""
        ref = self.ref[i]
        if ref < 0:
            return raster_pixels(self.extra[-ref - 1])
        if isinstance(self.base, list):
            return raster_pixels(self.base[ref])
        return self.base.pixels(ref)

    def __getitem__(self, i: int) -> Segment | CubicSegment:
        if not 0 <= i < len(self):
            raise IndexError(i)
        return self.segment(i)

    def __iter__(self) -> Iterator[Segment | CubicSegment]:
        return self.segments()

    def segments(self, start: int = 0, stop: int | None = None) -> Iterator[Segment | CubicSegment]:
        for i in range(start, len(self) if stop is None else stop):
            yield self.segment(i)

    def numpy(self) -> dict[str, np.ndarray]:
        """n and line as numpy views."""
        return {
            "n": np.frombuffer(self.n, dtype=np.uint32) if len(self) else np.zeros(0, np.uint32),
            "line": np.frombuffer(self.line, dtype=np.int32)
            if len(self)
            else np.zeros(0, np.int32),
        }

    @property
    def ticks(self) -> int:
        return int(np.sum(self.numpy()["n"], dtype=np.int64))
