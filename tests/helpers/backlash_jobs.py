"""Jobs on the emulator with a simulated machine whose backlash only the simulation knows, shared by the backlash
tests and benchmark: a job run with its trace, the carriage's path error, and the acceleration of every axis at
every tick of the stream as sent (from the firmware's own segment states) and as the trace shows it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from backlash_helpers import (
    STEPS_PER_MM, TICK_HZ, backlash_config, carriage_xy, polyline_error, pushed_plus, radial_error, write_sim,
)
from machine_helpers import read_trace_with_carriage
from quadstep.config import MachineConfig
from quadstep.emulator import Emulator
from quadstep.kernel.engine_model import predict, segment_steps
from quadstep.gcode import parse_gcode
from quadstep.machine import Target, open_machine
from quadstep.machine.takeups import StreamPlan
from quadstep.planner.plan import Plan, plan_program
from quadstep.planner.segments import SegmentArrays
from quadstep.planner.stream import Stream
from quadstep.kernel.fixed import D
from quadstep.protocol.cubic import CubicSegment
from quadstep.kernel.fixed import SIGMA
from quadstep.kernel.cubic_chain import CubicChain
from quadstep.protocol.segment import Segment


@dataclass
class Ran:
    """A job run on the emulator: as planned, as streamed, how it ended, its trace and the machine's summary."""

    config: MachineConfig
    backlash_steps: tuple[float, ...]
    plan: Plan
    sent: StreamPlan
    ended_by: str
    rows: np.ndarray  # (tick, axis, direction, motor, carriage)
    summary: dict[str, Any]

    def carriage(self, first: int, last: int) -> tuple[np.ndarray, np.ndarray]:
        """The carriage's (x, y) after every step between motion ticks first … last, in steps of the motor's
        frame (it began pushed +, half its band behind the motor)."""
        half = (self.backlash_steps[0] / 2, self.backlash_steps[1] / 2)
        ticks, x, y = carriage_xy(self.rows, (-half[0], -half[1]))
        inside = (ticks >= first) & (ticks <= last)
        return x[inside] + half[0], y[inside] + half[1]


def run_job(work: Path, name: str, gcode: str, mm: tuple[float, float, float], compensate: bool,
            binary: Path | None = None) -> Ran:
    """`gcode` on a free-running emulator whose machine has `mm` of backlash (every carriage pushed + at the
    start, as the machine is told), with its trace."""
    config = backlash_config(mm, compensate=compensate)
    steps = tuple(b * STEPS_PER_MM for b in mm)
    sim = write_sim(work / f"{name}.toml", steps)
    trace = work / f"{name}.csv"
    emu = Emulator(binary=binary, free=True, tick_hz=TICK_HZ, axes=3, trace=trace,
                   extra_args=["--machine", str(sim)]).start()
    try:
        with open_machine(Target(emulator=True), config, emulator=emu) as machine:
            machine.takeups.reset(pushed_plus(config))
            program = parse_gcode(gcode, config.axis_names, machine.position, config.arc_tolerance)
            plan = plan_program(program, config, machine.position)
            job = machine.run_job(plan)
            end = job.wait(300)
    finally:
        summary = emu.stop()
    return Ran(config, steps, plan, job.plan, end.ended_by if end is not None else "unknown",
               read_trace_with_carriage(trace), summary)


def line_ticks(stream: Stream | SegmentArrays, first_line: int, last_line: int) -> tuple[int, int]:
    """The motion ticks from the start of `first_line`'s segments to the end of `last_line`'s."""
    arrays = stream.numpy()
    ends = np.cumsum(arrays["n"].astype(np.int64))
    inside = np.flatnonzero((arrays["line"] >= first_line) & (arrays["line"] <= last_line))
    return int(ends[inside[0]] - arrays["n"][inside[0]]), int(ends[inside[-1]])


def circle_error(ran: Ran, radius_mm: float, first_line: int, last_line: int, margin: int = 0) -> float:
    """The carriage's largest radial error (steps) along the circle drawn by those lines, less `margin` ticks at
    each end."""
    first, last = line_ticks(ran.sent.segments, first_line, last_line)
    x, y = ran.carriage(first + margin, last - margin)
    return float(np.max(np.abs(radial_error(x, y, radius_mm * STEPS_PER_MM))))


def stepper_circle_error(plan: Plan, radius_mm: float, first_line: int, last_line: int) -> float:
    """What the steppers alone make of that circle: its largest radial error (steps) in the planned steps,
    without backlash or take-ups (the chords, each axis within half a step of its ideal)."""
    rows = predict(plan.segments.segments(), axis_count=plan.segments.axis_count).steps
    motor = np.zeros(len(rows))
    for axis in (0, 1):
        mine = rows[:, 1] == axis
        motor[mine] = np.cumsum(rows[mine, 2])
    first, last = line_ticks(plan.segments, first_line, last_line)
    ticks, x, y = carriage_xy(np.column_stack([rows, motor, motor]))
    inside = (ticks >= first) & (ticks <= last)
    return float(np.max(np.abs(radial_error(x[inside], y[inside], radius_mm * STEPS_PER_MM))))


def path_error(ran: Ran, corners_mm: np.ndarray, first_line: int, last_line: int) -> float:
    """The carriage's largest distance (steps) from the polyline through `corners_mm` along those lines."""
    x, y = ran.carriage(*line_ticks(ran.sent.segments, first_line, last_line))
    return float(np.max(polyline_error(x, y, corners_mm * STEPS_PER_MM)))


def stream_accel(segments: list[Segment | CubicSegment], axis_count: int) -> tuple[np.ndarray, np.ndarray]:
    """(start tick of every segment, [segment, axis, 2] signed acceleration at its first and last tick in
    steps/tick²): quadratic segments from their speeds, cubic ones from the chain's state and jerk."""
    chain = CubicChain(axis_count)
    starts = np.zeros(len(segments), dtype=np.int64)
    accel = np.zeros((len(segments), axis_count, 2))
    tick = 0
    for k, seg in enumerate(segments):
        starts[k] = tick
        if isinstance(seg, CubicSegment):
            for axis, (state, r) in enumerate(chain.starts(seg)):
                accel[k, axis] = [state.direction * state.d / SIGMA,
                                  state.direction * (state.d + (seg.n - 1) * r) / SIGMA]
            chain.advance(seg)
        else:
            for mv in seg.axes:
                accel[k, mv.axis] = mv.direction * (mv.vn - mv.v0) / D / seg.n
            chain.follow_quadratic(seg, {mv.axis: segment_steps(seg.n, mv) for mv in seg.axes})
        tick += seg.n
    return starts, accel


def peak_accel_mm(starts: np.ndarray, accel: np.ndarray, axis: int, first: int, ticks: int) -> float:
    """The largest |acceleration| (mm/s²) of `axis` over motion ticks first … first + ticks."""
    ends = np.append(starts[1:], starts[-1] + (1 << 40))
    inside = (ends > first) & (starts <= first + ticks)
    return float(np.max(np.abs(accel[inside, axis]))) * TICK_HZ**2 / STEPS_PER_MM


def motor_by_tick(rows: np.ndarray, axis: int, ticks: int) -> np.ndarray:
    """An axis's motor position after every motion tick 0 … ticks, from a trace's (tick, axis, direction) rows."""
    mine = rows[rows[:, 1] == axis]
    delta = np.zeros(ticks + 1, dtype=np.int64)
    np.add.at(delta, mine[:, 0].astype(np.int64), mine[:, 2].astype(np.int64))
    return np.cumsum(delta)


def trace_accel_mm(motor: np.ndarray, first: int, ticks: int, h: int) -> float:
    """The largest |second difference| of the motor over `h` ticks (mm/s²) centred in first … first + ticks:
    an average of the acceleration, within 2/h² step/tick² of it (each step within half a step of the ideal)."""
    centre = np.arange(max(first, h), min(first + ticks, motor.size - 1 - h) + 1)
    if centre.size == 0:
        return 0.0
    second = motor[centre + h] - 2 * motor[centre] + motor[centre - h]
    return float(np.max(np.abs(second))) / h**2 * TICK_HZ**2 / STEPS_PER_MM


def takeup_accel(ran: Ran, smoothing_ticks: int) -> dict[int, tuple[float, float]]:
    """Per axis with take-ups: the largest |acceleration| (mm/s²) during them, from the stream's segment states
    (exact) and from the trace's second differences over `smoothing_ticks` (an average, within
    2/h² step/tick² of it)."""
    stream = ran.sent.segments
    starts, accel = stream_accel(list(stream.segments()), stream.axis_count)
    ticks = int(ran.rows[-1, 0]) + smoothing_ticks + 1
    motors = {axis: motor_by_tick(ran.rows, axis, ticks) for axis in range(stream.axis_count)}
    out: dict[int, tuple[float, float]] = {}
    for t in ran.sent.compensated.takeups:
        motor = motors[t.axis]
        exact = peak_accel_mm(starts, accel, t.axis, t.start, t.ticks)
        seen = trace_accel_mm(motor, t.start, t.ticks, smoothing_ticks)
        before = out.get(t.axis, (0.0, 0.0))
        out[t.axis] = (max(before[0], exact), max(before[1], seen))
    return out


def plan_lag(ran: Ran) -> float:
    """The carriage's largest distance (steps) from where the plan has it at the same moment: the stream's ticks
    mapped back onto the plan's (less the anchor tick and the ticks added for take-ups at rest, in which the plan
    stands still), the carriage in the motor's frame (it began pushed +). 0 where every take-up runs while its axis
    stands still; a take-up superposed on the motion makes its carriage lag behind the plan by at most its size."""
    stream_ticks = int(ran.sent.segments.ticks)
    added = np.zeros(stream_ticks + 1, dtype=np.int64)  # ticks of the stream that the plan does not have
    takeups = ran.sent.compensated.takeups
    if takeups:
        added[0:] += 1  # the anchor tick
    blocks = {t.start: t.ticks + 1 for t in takeups if t.kind == "rest"}
    for start, length in blocks.items():
        inside = np.arange(start, min(start + length, stream_ticks + 1))
        added[inside] += inside - start + 1
        added[start + length :] += length
    base_tick = np.clip(np.arange(stream_ticks + 1) - added, 0, None)
    planned_rows = predict(ran.plan.segments.segments(), axis_count=ran.plan.segments.axis_count).steps
    worst = np.zeros(stream_ticks + 1)
    for axis in (0, 1):
        planned = motor_by_tick(planned_rows, axis, int(base_tick.max()))[base_tick]
        mine = ran.rows[ran.rows[:, 1] == axis]
        carriage = np.zeros(stream_ticks + 1)
        if mine.size:
            change = np.diff(np.concatenate([[-ran.backlash_steps[axis] / 2], mine[:, 4]]))
            np.add.at(carriage, mine[:, 0].astype(np.int64), change)
        carriage = np.cumsum(carriage)
        worst = np.hypot(worst, carriage - planned)
    return float(np.max(worst))
