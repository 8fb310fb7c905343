"""Helpers for the loopback tests: random segment streams, the emulator's step trace, and the check
that the trace is, step for step, what the host predicted."""

from __future__ import annotations

import random
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from quadstep.kernel.engine_model import Prediction, predict
from quadstep.protocol import CubicSegment, Segment
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove


def random_segments(rng: random.Random, count: int, axis_count: int = 4) -> list[Segment]:
    """`count` valid segments on 1..axis_count axes; the last one ends at rest."""
    segments = []
    for i in range(count):
        n = rng.choice([1, 2, N_MAX, rng.randint(1, N_MAX), rng.randint(1, 64), rng.randint(1, 300)])
        axes = sorted(rng.sample(range(axis_count), rng.randint(1, axis_count)))
        moves = []
        for axis in axes:
            v0 = rng.choice([0, D, rng.randint(0, D)])
            vn = 0 if i == count - 1 else rng.choice([0, D, rng.randint(0, D)])
            r = rng.choice([-D, D, 0, rng.randint(-D, D)])
            if r == D and v0 == D and vn == D:
                r = 0
            moves.append(AxisMove(axis=axis, direction=rng.choice([1, -1]), v0=v0, vn=vn, r=r))
        segments.append(Segment(n=n, axes=tuple(moves)))
    return segments


def read_trace(path: Path) -> np.ndarray:
    """The emulator's step trace as rows of (tick, axis, direction); none at all is fine."""
    lines = path.read_text().split("\n", 1)
    assert lines[0] == "tick,axis,direction"
    body = lines[1].strip() if len(lines) > 1 else ""
    if not body:
        return np.empty((0, 3), dtype=np.int64)
    return np.array([row.split(",") for row in body.split("\n")], dtype=np.int64).reshape(-1, 3)


def assert_trace_is_prediction(
    trace: Path | np.ndarray,
    segments: Iterable[Segment | CubicSegment],
    positions: Sequence[int] | None = None,
    *,
    axis_count: int | None = None,
    min_steps: int = 1,
) -> Prediction:
    """The emulator's steps (its trace file, or rows already read) are exactly the host's prediction
    of `segments` from `positions`: the same ticks, axes and directions, at least `min_steps` of
    them. Returns the prediction for further checks."""
    expected = predict(segments, positions) if axis_count is None else predict(
        segments, positions, axis_count=axis_count
    )
    got = read_trace(trace) if isinstance(trace, Path) else trace
    assert got.shape == expected.steps.shape, f"{len(got)} steps traced, {len(expected.steps)} predicted"
    assert len(got) >= min_steps
    assert np.array_equal(got, expected.steps)
    return expected


class RawPort:
    """The emulator's port without a Link: write any bytes, collect decoded reports."""

    def __init__(self, url: str) -> None:
        import serial

        from quadstep.protocol import Decoder

        self.port = serial.serial_for_url(url, timeout=0.05)
        self.decoder = Decoder("to_host")

    def write(self, data: bytes) -> None:
        self.port.write(data)

    def collect(self, count: int, timeout: float = 3.0) -> list:
        """The next `count` decoded reports (Frame or DecodeError)."""
        import time

        items: list = []
        deadline = time.monotonic() + timeout
        while len(items) < count and time.monotonic() < deadline:
            items += self.decoder.feed(self.port.read(self.port.in_waiting or 1))
        assert len(items) >= count, f"only {len(items)} of {count} reports: {items}"
        return items

    def close(self) -> None:
        self.port.close()

    def __enter__(self) -> RawPort:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
