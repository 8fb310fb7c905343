"""The rapid and spindle overrides during a job: what is not yet sent is planned again from a move
boundary (as for the feed override), the rapids at 25 % or the S scaled, and streamed after what was
sent without a stop. The emulator's trace is the prediction of the stream as sent, every move lands
exactly, the rapids after the change take as long as the re-plan says, and the spindle's duty changes
at the boundary the re-plan chose."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from host_helpers import read_trace
from waiting import wait_until

from quadstep.config import MachineConfig, load_config
from quadstep.kernel.engine_model import predict
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import JobRun, Machine
from quadstep.machine.override import replan_from
from quadstep.planner.feed_override import Overrides, apply_overrides
from quadstep.planner.plan import Plan, plan_program
from quadstep.planner.program import Program
from quadstep.protocol import Output

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
CONFIG_S = CONFIG.model_copy(update={"spindle": CONFIG.spindle.model_copy(update={"s_max": 1000.0})})
# feed moves to change the override on, then long rapids (and feed moves for the spindle job)
RAPIDS = "G21 G90 F1200\nG1 X6\nG1 X12 Y1\nG1 X18 Y0\nG1 X24 Y1\nG0 X40 Y0\nG0 X0 Y0\n"
SPINDLE = "G21 G90 F1200\nS500 M3\n" + "".join(f"G1 X{6 * k} Y{k % 2}\n" for k in range(1, 9)) + "M5\n"


def read_outputs(path: Path) -> list[tuple[int, int, int]]:
    rows = np.loadtxt(path, delimiter=",", skiprows=1, dtype=np.int64, ndmin=2)
    return [tuple(int(v) for v in row) for row in rows.reshape(-1, 3)]


def matching_boundary(program: Program, plan: Plan, sent: Plan, overrides: Overrides) -> int:
    """The move boundary the job planned its rest again from: the one whose re-plan is `sent`."""
    config = plan.config

    def scale(rest: Program, start: tuple[int, ...]) -> Program:
        return apply_overrides(rest, overrides, config, start)

    for move in range(1, plan.moves):
        again = replan_from(program, plan, move, scale, "line")
        if list(again.move_ends) == list(sent.move_ends) and np.array_equal(
            again.segments.numpy()["n"], sent.segments.numpy()["n"]
        ):
            return move
    raise AssertionError("no boundary's re-plan is the plan streamed")


def run_job(start_emulator, tmp_path: Path, config: MachineConfig, gcode: str, after_line: int,
            change: Callable[[Machine], object], outputs: bool = False):
    trace, out = tmp_path / "trace.csv", tmp_path / "outputs.csv"
    extra = ["--outputs", str(out)] if outputs else []
    emu = start_emulator(trace=trace, axes=3, tick_hz=config.tick_hz, extra_args=extra)
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        program = parse_gcode(gcode, config.axis_names, config.to_mm(machine.position),
                              config.arc_tolerance)
        plan = plan_program(program, config, machine.position)
        run = machine.run_job(plan, program)
        wait_until(lambda: run.progress.line >= after_line)
        asked_at = link.segments_done  # the board's count of segments done as the change is asked
        change(machine)
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == plan.end
    emu.stop()
    return program, plan, run, read_trace(trace), asked_at, (read_outputs(out) if outputs else [])


def ticks_of(plan: Plan, first: int, last: int) -> int:
    """The ticks of the plan's moves `first` … `last` - 1."""
    n = plan.segments.numpy()["n"].astype(np.int64)
    ends = [0, *plan.move_ends]
    return int(n[ends[first]:ends[last]].sum())


def test_a_rapid_override_mid_job_slows_the_rapids_not_yet_sent_and_lands_exactly(
        start_emulator, tmp_path: Path) -> None:
    program, plan, run, trace, asked_at, _ = run_job(
        start_emulator, tmp_path, CONFIG, RAPIDS, 2, lambda m: m.set_rapid_override(25))
    assert isinstance(run, JobRun)
    sent = run.plan.base
    move = matching_boundary(program, plan, sent, Overrides(rapid=25))
    # what the board did is the prediction of the stream as sent, and ends on the last target
    predicted = predict(list(run.plan.segments.segments()), axis_count=3)
    assert np.array_equal(trace, predicted.steps)
    assert tuple(predicted.positions) == plan.end
    assert int(trace[-1, 0]) <= int(sent.segments.numpy()["n"].astype(np.int64).sum())
    # the two rapids (the last two moves) take as long as the re-plan says: far longer than planned
    rapids_before, rapids_after = ticks_of(plan, 4, 6), ticks_of(sent, 4, 6)
    assert move <= 4 and rapids_after > 3 * rapids_before
    # the feed moves before the boundary ran as planned
    assert ticks_of(sent, 0, move) == ticks_of(plan, 0, move)
    # the long rapid cruises at a quarter of X's max_speed
    rows = trace[trace[:, 1] == 0]
    x = np.cumsum(rows[:, 2])
    cruise = rows[(x > 28 * 400) & (x <= 34 * 400) & (rows[:, 2] > 0)]
    speed = (len(cruise) - 1) / (cruise[-1, 0] - cruise[0, 0]) * CONFIG.tick_hz / 400
    assert speed == pytest.approx(CONFIG.axes[0].max_speed * 0.25, rel=0.02)
    ends = np.cumsum(sent.segments.numpy()["n"], dtype=np.int64)
    latency = int(ends[sent.move_ends[move - 1] - 1]) - (int(ends[asked_at - 1]) if asked_at else 0)
    print(f"\nrapid override: move boundary {move}, first changed tick {latency} ticks "
          f"({latency / CONFIG.tick_hz * 1000:.0f} ms) after the board's segment when asked")


def test_a_spindle_override_mid_job_scales_the_duty_from_the_boundary_on(
        start_emulator, tmp_path: Path) -> None:
    program, plan, run, trace, asked_at, changes = run_job(
        start_emulator, tmp_path, CONFIG_S, SPINDLE, 3, lambda m: m.set_spindle_override(150),
        outputs=True)
    sent = run.plan.base
    assert np.array_equal(trace, predict(list(run.plan.segments.segments()), axis_count=3).steps)
    # S500 of 1000, then 150 % of it from a move boundary on, then off at M5
    half, more = round(65535 * 0.5), round(65535 * 0.75)
    assert [(pins, duty) for _, pins, duty in changes] == [
        (int(Output.ON), half), (int(Output.ON), more), (0, 0)]
    ends = np.cumsum(sent.segments.numpy()["n"], dtype=np.int64)
    boundaries = [int(ends[i - 1]) for i in sent.move_ends[:-1]]
    assert changes[1][0] in boundaries
    move = boundaries.index(changes[1][0]) + 1
    asked_tick = int(ends[asked_at - 1]) if asked_at else 0
    assert changes[1][0] > asked_tick  # not before it was asked
    # the motion is as planned: the spindle override changes no move
    assert np.array_equal(sent.segments.numpy()["n"], plan.segments.numpy()["n"])
    latency = changes[1][0] - asked_tick
    print(f"\nspindle override: move boundary {move}, duty changed {latency} ticks "
          f"({latency / CONFIG.tick_hz * 1000:.0f} ms) after the board's segment when asked")


def test_in_laser_mode_the_spindle_override_scales_the_power_of_every_move_not_yet_sent(
        start_emulator, tmp_path: Path) -> None:
    """Laser mode: an S per move (400, 800, alternating) that runs on without stopping; at 50 % the
    moves after the boundary run at 200 and 400, and the motion is the one planned."""
    laser = CONFIG.model_copy(update={"spindle": CONFIG.spindle.model_copy(
        update={"s_max": 1000.0, "laser": True})})
    gcode = "G21 G90 F1200 M3\n" + "".join(
        f"G1 X{6 * k} Y{k % 2} S{400 if k % 2 else 800}\n" for k in range(1, 11)) + "M5\n"
    program, plan, run, trace, asked_at, changes = run_job(
        start_emulator, tmp_path, laser, gcode, 3, lambda m: m.set_spindle_override(50), outputs=True)
    sent = run.plan.base
    sent = run.plan.base
    assert np.array_equal(trace, predict(list(run.plan.segments.segments()), axis_count=3).steps)
    assert np.array_equal(sent.segments.numpy()["n"], plan.segments.numpy()["n"])  # no stop added
    ends = np.cumsum(sent.segments.numpy()["n"], dtype=np.int64)
    duty = {s: round(65535 * s / 1000) for s in (200, 400, 800)}
    on = [(tick, d) for tick, pins, d in changes if pins & Output.ON]
    boundary = next(tick for tick, d in on if d == duty[200])  # the first move at 50 %
    assert boundary in [int(ends[i - 1]) for i in sent.move_ends[:-1]]
    assert {d for tick, d in on if tick < boundary} == {duty[400], duty[800]}
    assert {d for tick, d in on if tick >= boundary} == {duty[200], duty[400]}
    assert boundary > (int(ends[asked_at - 1]) if asked_at else 0)
    assert changes[-1][1:] == (0, 0)
