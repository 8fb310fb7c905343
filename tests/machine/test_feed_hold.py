"""Feed hold and resume: a hold keeps the rest of the job; resume plans what is left from the rest position (a
fresh acceleration) and every remaining move lands exactly. From the host (JobRun.feed_hold) and from the board's
feed hold button (the simulated machine presses it); the cycle start button resumes."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from host_helpers import read_trace
from waiting import wait_until

from quadstep.config import MachineConfig, load_config
from quadstep.kernel.engine_model import predict, predict_hold
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.machine.remainder import plan_remainder
from quadstep.machine.units import hold_decels
from quadstep.protocol import HoldDone, HoldDoneAlong, Input, InputCause, InputChange

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
JOB = "G21 G90 F3000\nG1 X20 Y10\nG2 X30 Y20 I5 J5\nG1 X5 Y25\nG1 Z-1 F600\nG0 Z0\nG0 X0 Y0\n"


def check_trace(trace: Path, plan, hold: HoldDone, program, run) -> None:  # noqa: ANN001
    """Before the hold the plan's steps, then the hold's, then the remainder's from the rest position. Where a
    busy computer let the board run dry on the way, it braked past what it was sent and the job came back from
    there: then the steps add up to the plan's end."""
    if JobState.STARVED in run.states.history:
        got = read_trace(trace)
        assert [int(got[got[:, 1] == axis, 2].sum()) for axis in range(3)] == list(plan.end)
        return
    segments = list(plan.segments.segments())
    decels = run.last_rest.hold_decels or hold_decels(CONFIG)  # along the path, or the button's own
    stop = predict_hold(segments, hold.hold_tick, decels, axis_count=3)
    assert stop.held is not None
    remainder = plan_remainder(program, plan, stop.held, tuple(stop.positions), "line")
    before = predict(segments, axis_count=3).steps
    after = predict(remainder.segments.segments(), stop.positions, start_tick=stop.motion_ticks, axis_count=3)
    expected = np.concatenate([before[before[:, 0] <= hold.hold_tick], stop.steps, after.steps])
    got = read_trace(trace)
    states = [s.value for s in run.states.history]
    assert np.array_equal(got, expected), f"{len(got)} steps traced, {len(expected)} expected; job states {states}"
    assert tuple(after.positions) == plan.end


def test_a_feed_hold_keeps_the_job_and_resume_finishes_it_exactly(start_emulator, tmp_path: Path) -> None:
    path = tmp_path / "job.gcode"
    path.write_text(JOB)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        job = load_job(path, CONFIG, machine.position)
        run = machine.run_job(job.plan, job.program)
        wait_until(lambda: run.progress.line >= 3, what="the arc under way")  # mid-job
        seen = machine.report_count(HoldDone)
        assert run.feed_hold()
        wait_until(lambda: run.held)
        hold = link.last_report(HoldDone)
        assert machine.report_count(HoldDone) == seen + 1 and hold is not None
        assert run.paused_at is not None and run.wait(0.3) is None  # held, not ended
        assert run.state is JobState.HELD and run.progress.state is JobState.HELD
        assert run.resume()
        assert not run.resume()  # resumed already: nothing waits
        end = run.wait(30)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == job.plan.end
        held_once = [JobState.STREAMING, JobState.HELD, JobState.RESUMING, JobState.STREAMING, JobState.DONE]
        assert run.states.history == held_once or JobState.STARVED in run.states.history
        assert run.states.history.count(JobState.HELD) == 1 and run.states.history[-1] is JobState.DONE
    emu.stop()
    check_trace(trace, job.plan, hold, job.program, run)


def test_the_feed_hold_button_holds_and_cycle_start_resumes(start_emulator, tmp_path: Path) -> None:
    path = tmp_path / "job.gcode"
    path.write_text(JOB)
    sim = tmp_path / "machine.toml"
    sim.write_text('[[press]]\ninput = "feed_hold"\nat_tick = 9000\nticks = 50\n')
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz,
                         extra_args=("--machine", str(sim)))
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        job = load_job(path, CONFIG, machine.position)
        run = machine.run_job(job.plan, job.program)
        wait_until(lambda: run.held)
        hold = link.last_report(HoldDone)
        assert hold is not None and hold.hold_tick >= 9000
        # The cycle start button, as the board reports it (the simulated machine presses at motion ticks only).
        run._on_report(InputChange(motion_ticks=hold.motion_ticks, active=1 << Input.CYCLE_START,
                                   changed=1 << Input.CYCLE_START, cause=InputCause.CYCLE_START,
                                   position=hold.position))
        end = run.wait(30)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == job.plan.end
    emu.stop()
    rows = np.loadtxt(trace, delimiter=",", skiprows=1, ndmin=2)[:, :3].astype(np.int64)  # (with motor, carriage)
    check_trace_rows = tmp_path / "steps.csv"
    np.savetxt(check_trace_rows, rows, delimiter=",", fmt="%d", header="tick,axis,direction", comments="")
    check_trace(check_trace_rows, job.plan, hold, job.program, run)


def test_quadstep_run_holds_on_sigusr1_and_resumes_on_sigusr2(start_emulator, tmp_path: Path) -> None:
    import os
    import signal
    import subprocess
    import sys

    path = tmp_path / "job.gcode"
    path.write_text(JOB)
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    cli = subprocess.Popen([sys.executable, "-m", "quadstep.cli", "run", str(path), "--config",
                            str(REPO / "examples" / "router-uno.toml"), "--port", emu.url],
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert cli.stdout is not None and "planned" in cli.stdout.readline()
    time.sleep(0.3)
    os.kill(cli.pid, signal.SIGUSR1)
    time.sleep(0.8)
    assert cli.poll() is None  # held, waiting
    os.kill(cli.pid, signal.SIGUSR2)
    out, err = cli.communicate(timeout=30)
    assert cli.returncode == 0, err
    assert "feed hold at line" in err and "every axis is exactly where the job put it" in out


def off_the_line(position: tuple[int, ...] | list[int], end: tuple[int, ...]) -> float:
    """Steps from `position` to the line from the origin to `end`, in the X Y plane."""
    return abs(position[0] * end[1] - position[1] * end[0]) / float(np.hypot(end[0], end[1]))


SCURVE = CONFIG.model_copy(update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)})


@pytest.mark.parametrize("config", [CONFIG, SCURVE], ids=["constant-acceleration", "s-curve"])
def test_a_feed_hold_on_a_diagonal_stops_on_its_line(config: MachineConfig, start_emulator, tmp_path: Path) -> None:
    """X three times as fast as Y: each axis braking on its own would leave the line by about 0.3 mm;
    HOLD_ALONG stops both together on it, and the job goes on from there, exactly. Planned as S-curves, the
    speeds of its cubic segments come from the firmware's chain, followed as they are sent."""
    path = tmp_path / "job.gcode"
    path.write_text("G21 G90 F2400\nG1 X30 Y10\nG1 X0 Y0\n")
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=config.tick_hz)
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        job = load_job(path, config, machine.position)
        corner = config.to_steps((30.0, 10.0, 0.0))
        run = machine.run_job(job.plan, job.program)
        # a third of the way along the diagonal, at full speed (an S-curve's ramp up takes 0.1 s)
        wait_until(lambda: link.status().position[0] >= corner[0] // 3, what="the diagonal under way")
        assert run.feed_hold()
        wait_until(lambda: run.held)
        hold = link.last_report(HoldDone)
        assert isinstance(hold, HoldDoneAlong), hold
        rest = run.last_rest
        assert rest is not None and rest.hold_decels is not None and rest.hold_tick == hold.hold_tick
        own = hold_decels(config)
        assert rest.hold_decels[0] == own[0] and rest.hold_decels[1] < own[1] / 2  # Y brakes gently
        assert 0 < hold.position[0] < corner[0]  # it stopped on the diagonal
        assert off_the_line(hold.position, corner) <= 1.0
        if not config.jerk_limited:  # the host predicts a hold from a quadratic segment exactly
            segments = list(job.plan.segments.segments())
            along = predict_hold(segments, hold.hold_tick, rest.hold_decels, axis_count=3)
            apart = predict_hold(segments, hold.hold_tick, own, axis_count=3)
            assert tuple(along.positions) == tuple(hold.position)
            assert off_the_line(apart.positions, corner) > 50  # about 120 steps, each axis on its own
        assert run.resume()
        end = run.wait(30)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == job.plan.end
    emu.stop()
    if config.jerk_limited:
        got = read_trace(trace)
        assert [int(got[got[:, 1] == axis, 2].sum()) for axis in range(3)] == list(job.plan.end)
    else:
        check_trace(trace, job.plan, hold, job.program, run)
