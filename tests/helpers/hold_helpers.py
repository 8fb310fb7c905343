"""Helpers for the HOLD tests: planned jobs, traces, and the checks every hold must pass."""

from __future__ import annotations

import csv
import math
import random
from pathlib import Path

import numpy as np
from host_helpers import read_trace

from quadstep.kernel.engine_model import advance, predict, predict_hold, residual
from quadstep.protocol import Event, Segment
from quadstep.kernel.fixed import D, DECEL_SHIFT, N_MAX
from quadstep.kernel.motion import AxisMove


def planned_job(rng: random.Random, ticks: int, axis_count: int = 4) -> list[Segment]:
    """About `ticks` ticks of motion from rest, with continuous speeds changing by a bounded amount per
    segment on every axis and exactly carried residuals, as a planner makes it; the last segment brings
    every axis to rest. (A reversal happens only at rest, so r = 4096 never meets full speed.)"""
    ideal = [0] * axis_count
    pos = [0] * axis_count
    speed = [0] * axis_count
    direction = [1] * axis_count
    target = [rng.randint(D // 4, D) for _ in range(axis_count)]
    segments: list[Segment] = []
    total = 0
    while True:
        n = rng.randint(100, N_MAX)
        last = total + n >= ticks
        moves = []
        for axis in range(axis_count):
            if speed[axis] == 0:
                direction[axis] = rng.choice([1, -1])
            step = 0.35 * n  # at most ~0.35/4096 step per tick² of acceleration
            if last:
                vn = 0
            else:
                vn = int(max(0, min(target[axis], speed[axis] + rng.uniform(-step, step * 1.5))))
            mv = AxisMove(axis=axis, direction=direction[axis], v0=speed[axis], vn=vn,
                          r=residual(ideal[axis], pos[axis], direction[axis]))
            ideal[axis], pos[axis] = advance(ideal[axis], pos[axis], n, mv)
            speed[axis] = mv.vn
            moves.append(mv)
        segments.append(Segment(n=n, axes=tuple(moves)))
        total += n
        if last:
            return segments


def read_events(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


def assert_deceleration_within(trace: np.ndarray, axis: int, start: int, end: int, decel: int) -> None:
    """From the step trace alone: over every window of ticks [t, t+2L] after the hold began, the
    positions' second difference is at least −a·L² − 2, where a = decel/2^24 step per tick² and 2 steps
    allow for the stepper being within ½ step of a smooth ideal at each of the three points.
    (The firmware's quantised deceleration never exceeds a: docs/FIXED_POINT.md §8.)"""
    a = decel / 2**DECEL_SHIFT
    rows = trace[(trace[:, 1] == axis) & (trace[:, 0] > start)]
    if len(rows) < 3:
        return
    window = max(20, int(math.sqrt(40 / a)))  # where a·L² is about 40 steps
    ticks = np.arange(start, end + 2 * window + 1)
    position = np.searchsorted(rows[:, 0], ticks, side="right")  # steps made by the end of each tick
    second = position[2 * window:] - 2 * position[window:-window] + position[: -2 * window]
    assert second.min() >= -a * window * window - 2, (
        f"axis {axis} decelerated faster than {decel}/2^24 step/tick²: second difference "
        f"{second.min()} over {window} ticks"
    )
    # Speed from step intervals: never rising during the hold (it only decelerates).
    intervals = np.diff(rows[:, 0])
    assert np.all(np.diff(intervals) >= -1), f"axis {axis} sped up during the hold"


def check_hold(trace_path: Path, segments: list[Segment], done: Event, decels: list[int],
               axis_count: int = 4) -> None:
    """Everything a hold must do, checked against the trace: exactly the predicted steps before and after
    the hold tick, the rest positions and tick, nothing after, and no axis beyond its deceleration."""
    pred = predict_hold(segments, done.hold_tick, decels, axis_count=axis_count)
    assert list(done.position) == pred.positions
    assert done.motion_ticks == pred.motion_ticks
    full = predict(segments, axis_count=axis_count)
    trace = read_trace(trace_path)
    before = trace[trace[:, 0] <= done.hold_tick]
    after = trace[trace[:, 0] > done.hold_tick]
    assert np.array_equal(before, full.steps[full.steps[:, 0] <= done.hold_tick])
    assert np.array_equal(after, pred.steps), "steps after the hold tick differ from the prediction"
    # Nothing after the last axis stopped: the queued tail never ran.
    assert len(trace) == 0 or trace[:, 0].max() <= done.motion_ticks
    if pred.held is not None:
        held = segments[pred.held]
        for mv in held.axes:
            assert np.all(after[after[:, 1] == mv.axis][:, 2] == mv.direction)
            assert_deceleration_within(trace, mv.axis, done.hold_tick, done.motion_ticks, decels[mv.axis])
