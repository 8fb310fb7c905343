"""A planned stream read back exactly, for the compensation stage: steps, speeds and the ideal per
axis.

The stream is quadratic segments (the planner's arrays, read with numpy) or any mix of SEGMENT and
CUBIC_SEGMENT (walked with the firmware's chain). For every segment: its ticks, each axis's signed
steps and largest acceleration; on demand: the exact advance of an axis over part of a segment (the
polynomial the take-up is added to), the ticks of its steps, and the firmware's chain state before
it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ..kernel.cubic_chain import AxisState, CubicChain, CubicStep, choose2
from ..kernel.cubic_model import cubic_step_ticks
from ..kernel.engine_model import step_ticks
from ..kernel.fixed import SIGMA, D
from ..kernel.motion import AxisMove
from ..planner.segments import SegmentArrays
from ..planner.stream import Stream
from ..protocol.cubic import CubicSegment
from ..protocol.segment import Segment

# advance over tick k: α + β·(k−1) + γ·C(k−1, 2), signed, 2^-31 step
Poly = tuple[Fraction, Fraction, Fraction]
Items = Sequence[Segment | CubicSegment] | Stream  # segments by index: a list, or a planned stream


@dataclass
class BaseStream:
    """Segments with what the stage reads from them, indexed by segment."""

    axis_count: int
    n: np.ndarray  # (S,) ticks
    steps: np.ndarray  # (S, A) signed steps of each axis
    accel: np.ndarray  # (S, A) largest |acceleration|, steps per tick²
    # (S + 1,) every axis at rest at the boundary before segment k (and at the end)
    rest_before: np.ndarray
    item: Items | SegmentArrays
    # mixed streams: the chain before each segment
    chains: list[CubicChain] = field(default_factory=list)
    # the firmware's chain where the stream begins, when it goes on from a stream before it (None:
    # at rest, e = 0)
    entry: CubicChain | None = None
    start: np.ndarray = field(init=False)  # (S + 1,) first tick of each segment
    position: np.ndarray = field(init=False)  # (S + 1, A) stepper before each segment, from 0

    def __post_init__(self) -> None:
        self.start = np.concatenate([[0], np.cumsum(self.n, dtype=np.int64)])
        zeros = np.zeros((1, self.axis_count), dtype=np.int64)
        self.position = np.vstack([zeros, np.cumsum(self.steps, axis=0, dtype=np.int64)])
        if isinstance(self.item, SegmentArrays):
            self._arrays = self.item.numpy()
            named = (
                self._arrays["axes"][:, None].astype(np.int64) >> np.arange(self.axis_count)
            ) & 1
            index = np.where(named == 1, np.arange(len(self))[:, None], -1)
            self._last_named = np.maximum.accumulate(index, axis=0) if len(self) else index

    def __len__(self) -> int:
        return len(self.n)

    @property
    def ticks(self) -> int:
        return int(self.start[-1])

    def segment(self, k: int) -> Segment | CubicSegment:
        return self.item.segment(k) if isinstance(self.item, SegmentArrays) else self.item[k]

    # --- one axis in one segment --------------------------------------------------------------

    def step_ticks(self, k: int, axis: int) -> np.ndarray:
        """Ticks 1..n of segment k at which `axis` steps."""
        seg = self.segment(k)
        if isinstance(seg, Segment):
            mv = next((m for m in seg.axes if m.axis == axis), None)
            return step_ticks(seg.n, mv) if mv is not None else np.zeros(0, dtype=np.int64)
        start, r = self.chain_before(k).starts(seg)[axis]
        return cubic_step_ticks(seg.n, CubicStep(axis, start, r, 0))

    def position_at(self, axis: int, tick: int) -> int:
        """The stepper of `axis` after motion tick `tick` (0 … ticks), from the stream's start."""
        tick = min(max(tick, 0), self.ticks)
        k = min(int(np.searchsorted(self.start, tick, side="right")) - 1, len(self) - 1)
        if k < 0:
            return 0
        into = tick - int(self.start[k])
        made = int(np.count_nonzero(self.step_ticks(k, axis) <= into)) if self.steps[k, axis] else 0
        return int(self.position[k, axis]) + (made if self.steps[k, axis] >= 0 else -made)

    def advance(self, k: int, axis: int, skip: int) -> Poly:
        """The ideal's advance of `axis` over the ticks of segment k after its first `skip`,
        signed."""
        seg = self.segment(k)
        if isinstance(seg, Segment):
            mv = next((m for m in seg.axes if m.axis == axis), None)
            if mv is None:
                return Fraction(0), Fraction(0), Fraction(0)
            return _quadratic_advance(seg.n, mv, skip)
        start, r = self.chain_before(k).starts(seg)[axis]
        sign = start.direction
        return (
            Fraction(sign * (start.i + skip * start.d + choose2(skip) * r)),
            Fraction(sign * (start.d + skip * r)),
            Fraction(sign * r),
        )

    # --- the firmware's state -----------------------------------------------------------------

    def chain_before(self, k: int) -> CubicChain:
        """The firmware's chain before segment k, given the chain at the stream's start: `entry`,
        else at rest with e = 0 (the stage begins every compensated stream that does not go on from
        another with a segment that makes it so)."""
        if self.chains:
            return self.chains[k].copy()
        chain = self.entry.copy() if self.entry is not None else CubicChain(self.axis_count)
        if k == 0:
            return chain
        a = self._arrays
        for axis in range(self.axis_count):
            j = int(self._last_named[k - 1, axis])
            if j < 0:  # not named since the start: at rest there, e carried
                chain.axes[axis].i = chain.axes[axis].d = 0
                continue
            v0, vn, r = int(a["v0"][j, axis]), int(a["vn"][j, axis]), int(a["r"][j, axis])
            n = int(a["n"][j])
            state = chain.axes[axis]
            state.e = (r + n * (v0 + vn) - 2 * D * abs(int(self.steps[j, axis]))) << 18
            state.direction = -1 if int(a["axes"][j]) & (16 << axis) else 1
            state.i = vn << 19 if j == k - 1 else 0
            state.d = 0
        return chain


def _quadratic_advance(n: int, mv: AxisMove, skip: int) -> Poly:
    """I(k) = σ·(2^19·v0 + 2^18·(vn − v0)·(2k − 1)/n) over the ticks after `skip`."""
    slope = Fraction((mv.vn - mv.v0) << 18, n)
    sign = mv.direction
    return sign * ((mv.v0 << 19) + slope * (2 * skip + 1)), sign * 2 * slope, Fraction(0)


def from_arrays(arrays: SegmentArrays, entry: CubicChain | None = None) -> BaseStream:
    """The planner's quadratic segments, read with numpy (`entry`: the chain they go on from)."""
    a = arrays.numpy()
    count = arrays.axis_count
    n = a["n"].astype(np.int64)
    bits = a["axes"].astype(np.int64)
    active = ((bits[:, None] >> np.arange(count)) & 1).astype(bool)
    sign = np.where((bits[:, None] >> (4 + np.arange(count))) & 1, -1, 1)
    v0, vn, r = (a[key].astype(np.int64) for key in ("v0", "vn", "r"))
    made = (r + n[:, None] * (v0 + vn) + D) // (2 * D)
    steps = np.where(active, sign * made, 0)
    accel = np.where(active, np.abs(vn - v0) / (D * np.maximum(n, 1)[:, None]), 0.0)
    still_end = np.all(~active | (vn == 0), axis=1)
    still_start = np.all(~active | (v0 == 0), axis=1)
    rest = np.concatenate([[True], still_end]) & np.concatenate([still_start, [True]])
    return BaseStream(count, n, steps.astype(np.int64), accel, rest, arrays, entry=entry)


def from_items(items: Items, axis_count: int) -> BaseStream:
    """Any mix of quadratic and cubic segments, walked with the firmware's chain from rest (e =
    0)."""
    chain = CubicChain(axis_count)
    chains: list[CubicChain] = []
    n = np.zeros(len(items), dtype=np.int64)
    steps = np.zeros((len(items), axis_count), dtype=np.int64)
    accel = np.zeros((len(items), axis_count))
    moving = np.zeros(len(items) + 1, dtype=bool)  # some axis moves at the boundary before k
    for k, seg in enumerate(items):
        chains.append(chain.copy())
        n[k] = seg.n
        if isinstance(seg, CubicSegment):
            starts = chain.starts(seg)
            moving[k] |= any(not s.at_rest for s, _ in starts)
            for step in chain.advance(seg):
                steps[k, step.axis] = step.start.direction * step.steps
                accel[k, step.axis] = (
                    max(abs(step.start.d), abs(step.start.d + seg.n * step.r)) / SIGMA
                )
            moving[k + 1] = any(not s.at_rest for s in chain.axes)
            continue
        totals = {}
        for mv in seg.axes:
            made = int((mv.r + seg.n * (mv.v0 + mv.vn) + D) // (2 * D))
            totals[mv.axis] = made
            steps[k, mv.axis] = mv.direction * made
            accel[k, mv.axis] = abs(mv.vn - mv.v0) / (D * seg.n)
            moving[k] |= mv.v0 > 0
            moving[k + 1] |= mv.vn > 0
        chain.follow_quadratic(seg, totals)
    chains.append(chain.copy())
    # a planned stream keeps its source lines
    kept = items if isinstance(items, Stream) else list(items)
    return BaseStream(axis_count, n, steps, accel, ~moving, kept, chains)


def rest_state(axis_count: int) -> list[AxisState]:
    return [AxisState() for _ in range(axis_count)]


__all__ = ["BaseStream", "Poly", "from_arrays", "from_items"]
