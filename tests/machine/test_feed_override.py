"""The feed override during a job: what is not yet sent is planned again from a move boundary, with every feed
scaled (rapids not), and streamed after what was sent without a stop. The emulator's trace is the host's
prediction of the stream as sent, every move lands exactly, and the cruise after the change is the new feed's."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from host_helpers import assert_trace_is_prediction, read_trace
from waiting import wait_until

from quadstep.config import AxisConfig, BacklashConfig, MachineConfig, load_config
from quadstep.kernel.engine_model import predict
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.planner.feed_override import check_percent, scale_feeds
from quadstep.planner.plan import plan_program
from quadstep.planner.program import LinearMove

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
FEED = 1200.0  # mm/min: 20 mm/s
# a zigzag of 6 mm steps along X: corners the look-ahead slows down for, each move long enough to cruise
def zigzag(feed: float) -> str:
    return f"G21 G90 F{feed:g}\n" + "".join(f"G1 X{6 * k} Y{k % 2}\n" for k in range(1, 13)) + "G0 X0 Y0\n"


ZIGZAG = zigzag(FEED)


def cruise_mm_s(steps: np.ndarray, axis: int, start: int, stop: int, config: MachineConfig) -> float:
    """The axis's speed over the middle third of the steps it makes from position `start` to `stop` (steps)."""
    rows = steps[steps[:, 1] == axis]
    position = np.cumsum(rows[:, 2])
    lo, hi = sorted((start, stop))
    third = (hi - lo) // 3
    index = np.flatnonzero((position > lo + third) & (position <= hi - third) & (rows[:, 2] == np.sign(stop - start)))
    index = index[: int(np.argmax(np.diff(index) > 1)) + 1] if np.any(np.diff(index) > 1) else index  # the first pass
    inside = rows[index]
    ticks = inside[-1, 0] - inside[0, 0]
    return float((len(inside) - 1) / ticks * config.tick_hz / config.axes[axis].steps_per_mm)


def run_with_override(start_emulator, tmp_path: Path, config: MachineConfig, gcode: str, percent: int,
                      after_line: int):
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=config.tick_hz)
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        program = parse_gcode(gcode, config.axis_names, config.to_mm(machine.position), config.arc_tolerance)
        plan = plan_program(program, config, machine.position)
        run = machine.run_job(plan, program)
        wait_until(lambda: run.progress.line >= after_line)
        assert run.set_feed_override(percent) == percent and run.feed_override == percent
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == plan.end
    emu.stop()
    return plan, run, read_trace(trace)


def test_overrides_in_quick_succession_on_a_deep_queue_end_exactly(start_emulator, tmp_path: Path) -> None:
    """Override after override while a 127-slot queue holds the job's whole lookahead: each continuation begins
    while the segments of the one it follows still run (its count of segments done is negative), and the job
    still ends done, on its last target, as the stream sent predicts."""
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=127)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        program = parse_gcode(ZIGZAG, CONFIG.axis_names, CONFIG.to_mm(machine.position), CONFIG.arc_tolerance)
        plan = plan_program(program, CONFIG, machine.position)
        run = machine.run_job(plan, program)
        wait_until(lambda: run.progress.line >= 2)
        for percent in (*range(90, 210, 10), 100):
            assert run.set_feed_override(percent) == percent
            time.sleep(0.05)
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == plan.end
    emu.stop()
    assert_trace_is_prediction(trace, run.plan.segments.segments(), axis_count=3)


@pytest.mark.parametrize("percent", [50, 150])
def test_an_override_mid_job_changes_the_cruise_of_what_is_not_sent_and_lands_exactly(
        start_emulator, tmp_path: Path, percent: int) -> None:
    plan, run, trace = run_with_override(start_emulator, tmp_path, CONFIG, ZIGZAG, percent, after_line=3)
    sent = run.plan.base
    assert len(sent) != len(plan)  # the tail was planned again and streamed
    # what the board did is the prediction of the stream as sent: the first part of the old, then the new
    predicted = predict(list(run.plan.segments.segments()), axis_count=3)
    assert np.array_equal(trace, predicted.steps)
    assert tuple(predicted.positions) == plan.end
    # every move lands on its target: the axes' positions at each move's end in the stream as sent
    ends = np.cumsum(sent.segments.numpy()["n"], dtype=np.int64)[np.asarray(sent.move_ends) - 1]
    targets = [CONFIG.to_steps(i.target) for i in run.program.items if isinstance(i, LinearMove)]
    for tick, target in zip(ends, targets):
        done = trace[trace[:, 0] <= tick]
        assert tuple(int(done[done[:, 1] == a, 2].sum()) for a in range(3)) == target
    # the first move ran at the programmed feed, the last feed move at the override's
    dx = 6 / np.sqrt(37)
    first = cruise_mm_s(trace, 0, 0, 6 * 400, CONFIG)
    last = cruise_mm_s(trace, 0, 66 * 400, 72 * 400, CONFIG)
    assert first == pytest.approx(FEED / 60 * dx, rel=0.03)
    assert last == pytest.approx(FEED / 60 * dx * percent / 100, rel=0.03)
    # the rapid back home is as fast either way (rapids have no feed override)
    assert cruise_mm_s(trace, 0, 72 * 400, 0, CONFIG) == pytest.approx(
        cruise_mm_s(predict(list(plan.segments.segments()), axis_count=3).steps, 0, 72 * 400, 0, CONFIG), rel=0.01)


def test_take_ups_are_redone_for_the_tail_planned_again(start_emulator, tmp_path: Path) -> None:
    """A machine with backlash on Y: every reversal of the zigzag has its take-up, in the tail planned again too
    (slower: the take-ups take longer to plan than the move from one boundary to the next, on a loaded host)."""
    axes = tuple(AxisConfig(name=a.name, steps_per_mm=a.steps_per_mm, max_speed=a.max_speed, max_accel=a.max_accel,
                            travel_min=a.travel_min, travel_max=a.travel_max,
                            backlash=BacklashConfig(mm=0.05) if a.name == "Y" else None) for a in CONFIG.axes)
    config = MachineConfig(tick_hz=CONFIG.tick_hz, junction_deviation=CONFIG.junction_deviation, axes=axes)
    plan, run, trace = run_with_override(start_emulator, tmp_path, config, zigzag(FEED / 2), 150, after_line=3)
    compensated = run.plan.compensated
    assert len(run.plan.base) != len(plan)
    assert len(compensated.takeups) == 11  # one at each reversal of Y, those of the tail planned again too
    assert np.array_equal(trace, predict(list(run.plan.segments.segments()), axis_count=3).steps)
    last = cruise_mm_s(trace, 0, 66 * 400, 72 * 400, config)
    assert last == pytest.approx(FEED / 2 / 60 * 6 / np.sqrt(37) * 1.5, rel=0.03)


def test_the_override_is_bounded_and_scales_feeds_only() -> None:
    assert check_percent(10) == 10 and check_percent(200) == 200
    for wrong in (9, 201, 0, -50):
        with pytest.raises(ValueError, match=r"feed override .* is outside 10–200 %"):
            check_percent(wrong)
    program = parse_gcode("G21 G90 F600\nG1 X5\nG0 X0\n", CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)
    feeds = [i.feed for i in scale_feeds(program, 150).items if isinstance(i, LinearMove)]
    assert feeds == [pytest.approx(15.0), None]  # mm/s; the rapid keeps none


def test_a_running_job_refuses_an_override_outside_the_bounds(start_emulator, tmp_path: Path) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, free=True)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        program = parse_gcode("G21 G90 F600\nG1 X2\n", CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)
        run = machine.run_job(plan_program(program, CONFIG, machine.position), program)
        for wrong in (5, 250):
            with pytest.raises(ValueError, match="outside 10–200 %"):
                run.set_feed_override(wrong)
        assert run.feed_override == 100
        end = run.wait(30)
        assert end is not None and end.ended_by == "done"


@pytest.mark.parametrize("percent", [60, 150])
def test_a_jerk_limited_job_takes_an_override_mid_job_and_lands_exactly(
        start_emulator, tmp_path: Path, percent: int) -> None:
    """An S-curve job: the rest planned again from a move boundary with the S-curve planner (the
    moves before it as they were), streamed after what was sent without a stop; the trace is the
    prediction of the stream as sent, every move lands on its target, and the last feed move
    cruises at the new feed."""
    config = MachineConfig(tick_hz=CONFIG.tick_hz, junction_deviation=CONFIG.junction_deviation,
                           axes=tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes))
    plan, run, trace = run_with_override(start_emulator, tmp_path, config, ZIGZAG, percent, after_line=3)
    sent = run.plan.base
    assert len(sent) != len(plan) or not np.array_equal(
        sent.segments.numpy()["n"], plan.segments.numpy()["n"])  # the tail was planned again
    predicted = predict(list(run.plan.segments.segments()), axis_count=3)
    assert np.array_equal(trace, predicted.steps)
    assert tuple(predicted.positions) == plan.end
    n = np.fromiter((s.n for s in sent.segments.segments()), dtype=np.int64)
    ends = np.cumsum(n)[np.asarray(sent.move_ends) - 1]
    targets = [config.to_steps(i.target) for i in run.program.items if isinstance(i, LinearMove)]
    for tick, target in zip(ends, targets):
        done = trace[trace[:, 0] <= tick]
        assert tuple(int(done[done[:, 1] == a, 2].sum()) for a in range(3)) == target
    dx = 6 / np.sqrt(37)
    last = cruise_mm_s(trace, 0, 66 * 400, 72 * 400, config)
    assert last == pytest.approx(FEED / 60 * dx * percent / 100, rel=0.03)
