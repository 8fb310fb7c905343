"""Compensation on the emulator with a simulated machine whose backlash only the simulation knows: the
carriage follows the path, the firmware makes the host's predicted steps, and every position reported is the
carriage's (take-ups excluded), through stops and from one connection to the next."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from backlash_helpers import (
    STEPS_PER_MM, backlash_config, carriage_xy, circle_gcode, pushed_plus, radial_error, write_sim,
)
from machine_helpers import read_trace_with_carriage
from quadstep.kernel.engine_model import predict
from quadstep.gcode import parse_gcode
from quadstep.machine import Target, open_machine
from quadstep.planner.plan import plan_program

B_STEPS = 40.0  # 0.1 mm
RADIUS = 20.0


def run_circle(start_emulator, tmp_path: Path, compensate: bool):  # noqa: ANN001, ANN201
    config = backlash_config((0.1, 0.1, 0.0), compensate=compensate)
    sim = write_sim(tmp_path / f"sim-{compensate}.toml", (B_STEPS, B_STEPS, 0.0))
    trace = tmp_path / f"trace-{compensate}.csv"
    emu = start_emulator(free=True, tick_hz=32_000, axes=3, trace=trace, extra_args=["--machine", str(sim)])
    machine = open_machine(Target(emulator=True), config, emulator=emu)
    machine.takeups.reset(pushed_plus(config))
    program = parse_gcode(circle_gcode(RADIUS, 10), config.axis_names, machine.position, config.arc_tolerance)
    plan = plan_program(program, config, machine.position)
    job = machine.run_job(plan)
    end = job.wait(120)
    machine.close()
    summary = emu.stop()
    return plan, job, end, machine, read_trace_with_carriage(trace), summary


def test_a_circle_the_carriage_on_the_path_with_compensation_off_by_the_backlash_without(start_emulator, tmp_path) -> None:  # noqa: ANN001
    plan, job, end, machine, rows, summary = run_circle(start_emulator, tmp_path, True)
    assert end is not None and end.ended_by == "done"
    assert machine.position == plan.end  # take-ups excluded: exactly where the job put the carriage
    predicted = predict(job.plan.segments.segments(), axis_count=3)
    assert np.array_equal(rows[:, :3].astype(np.int64), predicted.steps)  # take-ups and all, step for step
    for axis in (0, 1):  # and the carriage is where it began, B/2 behind the motor that pushed it in +
        assert summary["machine"]["axes"][axis]["carriage"] == plan.end[axis] - B_STEPS / 2
    ticks, x, y = carriage_xy(rows)
    on_circle = (ticks > 40_000) & (ticks < ticks[-1] - 30_000)
    error = radial_error(x + B_STEPS / 2, y + B_STEPS / 2, RADIUS * STEPS_PER_MM)[on_circle]

    plain, plain_job, plain_end, _, plain_rows, _ = run_circle(start_emulator, tmp_path, False)
    assert plain_end is not None and plain_end.ended_by == "done" and plain_job.plan.compensated.takeups == []
    ticks, x, y = carriage_xy(plain_rows)
    off = radial_error(x + B_STEPS / 2, y + B_STEPS / 2, RADIUS * STEPS_PER_MM)[(ticks > 40_000) & (ticks < ticks[-1] - 30_000)]
    assert 0.8 * B_STEPS <= np.max(np.abs(off)) <= 1.2 * B_STEPS  # without: off by the backlash where it reverses
    motor = plain_rows.copy()
    motor[:, 4] = plain_rows[:, 3]
    ticks, x, y = carriage_xy(motor)
    stepper = radial_error(x, y, RADIUS * STEPS_PER_MM)[(ticks > 40_000) & (ticks < ticks[-1] - 30_000)]
    # with: what the steppers themselves make of the circle (the chords, the plan's rounding), no more
    assert np.max(np.abs(error)) <= np.max(np.abs(stepper)) + 0.01
    assert np.max(np.abs(error)) <= 1.0 + machine.config.arc_tolerance * STEPS_PER_MM + 0.25


def test_a_stop_inside_a_take_up_and_the_next_connection_know_where_the_carriage_is(start_emulator, tmp_path) -> None:  # noqa: ANN001
    config = backlash_config((0.1, 0.0, 0.0), accel=2.0)  # a take-up of about 0.45 s: room to stop inside it
    sim = write_sim(tmp_path / "sim.toml", (B_STEPS, 0.0, 0.0))
    emu = start_emulator(tick_hz=32_000, axes=3, extra_args=["--machine", str(sim)])  # real time
    state = tmp_path / "state.json"
    with open_machine(Target(emulator=True), config, emulator=emu, state_file=state) as machine:
        machine.takeups.reset(pushed_plus(config))
        moves = plan_program(parse_gcode("G1 X-1 F1200\n", config.axis_names, machine.position, 1e-3), config,
                             machine.position)
        motion = machine.move(moves.segments)
        while machine.status().position[0] == 0:  # the motor's first step of the take-up at the move's start
            time.sleep(0.002)
        stopped = motion.halt()
        assert stopped.held and 0 < machine.takeups.band.axes[0].w < 40  # the motor stopped inside the band
        shown = machine.position
    with open_machine(Target(emulator=True), config, emulator=emu, state_file=state) as again:
        assert again.position == shown and again.takeups.band == machine.takeups.band  # kept in the state file
        back = plan_program(parse_gcode("G1 X0 F1200\n", config.axis_names, again.position, 1e-3), config,
                            again.position)
        assert again.move(back.segments).wait(30).ended_by == "done"
        assert again.position == (0, 0, 0)
    summary = emu.stop()
    assert summary["machine"]["axes"][0]["carriage"] == -B_STEPS / 2  # where it began: pushed +, at 0


def test_homing_leaves_the_band_known_and_the_pull_off_exact(start_emulator, tmp_path) -> None:  # noqa: ANN001
    from quadstep.config import HomingConfig, InputsConfig
    from quadstep.machine.homing import home

    config = backlash_config((0.1, 0.0, 0.0))
    axis = config.axes[0].model_copy(update={"homing": HomingConfig(end="min", seek=10, locate=1, pull_off=1,
                                                                    switch_at=0.0)})
    config = config.model_copy(update={"axes": (axis, *config.axes[1:]),
                                       "inputs": InputsConfig(debounce_ms=2)})
    sim = write_sim(tmp_path / "sim.toml", (B_STEPS, 0.0, 0.0), "") .read_text().replace(
        "backlash = 40.0\n", "backlash = 40.0\n[axis.limit_min]\nat = -2000.0\nhysteresis = 5\nbounce = 2\n", 1)
    (tmp_path / "sim.toml").write_text(sim)
    emu = start_emulator(free=True, tick_hz=32_000, axes=3, extra_args=["--machine", str(tmp_path / "sim.toml")])
    with open_machine(Target(emulator=True), config, emulator=emu) as machine:
        home(machine, ["X"])
        # pulled off 1 mm from where the locating approach came to rest (just past the switch's point)
        assert STEPS_PER_MM - 10 <= machine.position[0] <= STEPS_PER_MM
        assert machine.takeups.band.axes[0].w == 40  # the pull-off left the carriage pushed +
        back = plan_program(parse_gcode("G1 X0.5 F600\n", config.axis_names, machine.position, 1e-3), config,
                            machine.position)
        assert machine.move(back.segments).wait(30).ended_by == "done"
        assert machine.takeups.band.axes[0].w == 0 and machine.position[0] == STEPS_PER_MM // 2
    summary = emu.stop()
    carriage = summary["machine"]["axes"][0]["carriage"]
    assert abs(carriage - (-2000 + 0.5 * STEPS_PER_MM)) <= 1  # the carriage 0.5 mm off the switch's point

