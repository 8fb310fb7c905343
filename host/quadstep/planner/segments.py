"""The planned job as compact arrays of segments; pydantic Segments built only on demand.

A few hundred thousand segments take about 21 bytes each for three axes
(n, axis byte, and v0/vn/r per axis), instead of a kilobyte as objects.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np

from ..kernel.motion import AxisMove
from ..protocol.segment import Segment


@dataclass
class SegmentArrays:
    """Column arrays; per-axis columns hold axis_count values per segment (0 for a still axis)."""

    axis_count: int
    n: array = field(default_factory=lambda: array("H"))
    # bits 0–3 active, 4–7 negative direction
    axes: array = field(default_factory=lambda: array("B"))
    v0: array = field(default_factory=lambda: array("H"))
    vn: array = field(default_factory=lambda: array("H"))
    r: array = field(default_factory=lambda: array("h"))
    line: array = field(default_factory=lambda: array("i"))  # source line of each segment

    def __len__(self) -> int:
        return len(self.n)

    @classmethod
    def of(cls, segments: Iterable[Segment], axis_count: int) -> SegmentArrays:
        """Protocol segments as arrays (raw segment files)."""
        out = cls(axis_count)
        for seg in segments:
            bits, v0, vn, r = 0, [0] * axis_count, [0] * axis_count, [0] * axis_count
            for move in seg.axes:
                bits |= 1 << move.axis | (16 << move.axis if move.direction < 0 else 0)
                v0[move.axis], vn[move.axis], r[move.axis] = move.v0, move.vn, move.r
            out.append(seg.n, bits, v0, vn, r, 0)
        return out

    def append(
        self, n: int, axes: int, v0: list[int], vn: list[int], r: list[int], line: int
    ) -> None:
        self.n.append(n)
        self.axes.append(axes)
        self.v0.extend(v0)
        self.vn.extend(vn)
        self.r.extend(r)
        self.line.append(line)

    def segment(self, i: int) -> Segment:
        """Segment i as the protocol model."""
        base = i * self.axis_count
        bits = self.axes[i]
        moves = tuple(
            AxisMove(
                axis=a,
                direction=-1 if bits & (16 << a) else 1,
                v0=self.v0[base + a],
                vn=self.vn[base + a],
                r=self.r[base + a],
            )
            for a in range(self.axis_count)
            if bits & (1 << a)
        )
        return Segment(n=self.n[i], axes=moves)

    def segments(self, start: int = 0, stop: int | None = None) -> Iterator[Segment]:
        for i in range(start, len(self) if stop is None else stop):
            yield self.segment(i)

    def pixels(self, i: int) -> int:
        """The powers segment i carries to the board's RASTER ring: none (arrays hold no RASTER
        line), without building the segment."""
        return 0

    def numpy(self) -> dict[str, np.ndarray]:
        """Zero-copy numpy views: n, axes, line (S,), v0, vn, r (S, axis_count)."""
        shape = (len(self), self.axis_count)
        return {
            "n": np.frombuffer(self.n, dtype=np.uint16) if len(self) else np.zeros(0, np.uint16),
            "axes": np.frombuffer(self.axes, dtype=np.uint8)
            if len(self)
            else np.zeros(0, np.uint8),
            "line": np.frombuffer(self.line, dtype=np.int32)
            if len(self)
            else np.zeros(0, np.int32),
            "v0": (
                np.frombuffer(self.v0, dtype=np.uint16) if len(self) else np.zeros(0, np.uint16)
            ).reshape(shape),
            "vn": (
                np.frombuffer(self.vn, dtype=np.uint16) if len(self) else np.zeros(0, np.uint16)
            ).reshape(shape),
            "r": (
                np.frombuffer(self.r, dtype=np.int16) if len(self) else np.zeros(0, np.int16)
            ).reshape(shape),
        }

    def nbytes(self) -> int:
        return sum(
            a.itemsize * len(a) for a in (self.n, self.axes, self.v0, self.vn, self.r, self.line)
        )
