"""An open job (JobRun.extend): lines given while it runs are planned onto what the board has not been
sent, without a stop; the emulator's trace is the host's prediction of the stream as sent and the job
ends on the last target. Given after the job ran everything, they are refused (a new job takes them);
given after the board was sent the end, they go on from rest."""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import numpy as np
import pytest
from host_helpers import assert_trace_is_prediction
from waiting import wait_until

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.planner.plan import plan_program
from quadstep.protocol.cubic import CubicSegment

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SCURVE = CONFIG.model_copy(
    update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)}
)


def zigzag(first: int, count: int) -> str:
    return "".join(f"G1 X{2 * k} Y{10 + k % 2}\n" for k in range(first, first + count))


@pytest.mark.realtime
def test_lines_given_while_it_runs_go_on_without_a_stop(start_emulator, tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        head = "G21 G90 F1800\n" + zigzag(1, 10)
        program = parse_gcode(head, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)
        run = machine.run_job(
            plan_program(program, CONFIG, machine.position), program, open_end=True
        )
        assert run.open
        whole = head + zigzag(11, 30)
        items = parse_gcode(whole, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance).items
        assert items[: len(program.items)] == program.items
        streams = [weakref.ref(run.plan.segments)]  # the stream of each plan the job ran
        for first in (11, 21, 31):  # ten lines at a time, each while the last ten still run
            wait_until(lambda: run.progress.line >= first - 6)
            at = len(program.items) + first - 11
            assert run.extend(items[at : at + 10], first + 10)
            wait_until(lambda: run.plan.segments is not streams[-1]())  # planned onto the job
            streams.append(weakref.ref(run.plan.segments))
        run.close()
        end = run.wait(60)
        assert end is not None and end.ended_by == "done", end
        gc.collect()  # once it ran: a full collection of this process stops it longer than 14 segments last
        # the plans run past are let go (a long stream would keep a copy of itself per addition)
        assert streams[0]() is None and streams[1]() is None
        planned = plan_program(
            parse_gcode(whole, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance),
            CONFIG,
            (0, 0, 0),
        )
        assert machine.position == planned.end
        assert not run.extend([], 50)  # ended: a new job takes what comes
    emu.stop()
    assert run.state is JobState.DONE and JobState.RESUMING not in run.states.history
    arrays = run.plan.base.segments.numpy()
    assert not np.any(np.abs(arrays["vn"][:-1]).sum(axis=1) == 0)  # no rest before the end
    assert_trace_is_prediction(trace, run.plan.segments.segments(), axis_count=3)
    assert run.plan.base.moves == planned.moves


@pytest.mark.realtime
@pytest.mark.parametrize("override", [None, 60])
def test_a_jerk_limited_job_goes_on_from_its_kept_state_without_a_stop(
    start_emulator, tmp_path: Path, override: int | None
) -> None:
    """max_jerk set: lines given while it runs go on from the S-curve planner's state the plan kept
    (planner/scurve_rest.py), not from rest; with a feed override among them too."""
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=SCURVE.tick_hz, queue=14)
    with Link.open(emu.url) as link:
        machine = Machine(link, SCURVE)
        head = "G21 G90 F1800\n" + zigzag(1, 10)
        whole = head + zigzag(11, 30)
        parsed = [
            parse_gcode(text, SCURVE.axis_names, (0.0, 0.0, 0.0), SCURVE.arc_tolerance)
            for text in (head, whole)
        ]
        program, items = parsed[0], parsed[1].items
        run = machine.run_job(
            plan_program(program, SCURVE, machine.position), program, open_end=True
        )
        plans = [run.plan.segments]
        for first in (11, 21, 31):
            wait_until(lambda: run.progress.line >= first - 6)
            at = len(program.items) + first - 11
            assert run.extend(items[at : at + 10], first + 10)
            if override is not None and first == 21:
                assert run.set_feed_override(override) == override
            wait_until(lambda: run.plan.segments is not plans[-1])  # planned onto the job
            plans.append(run.plan.segments)
        run.close()
        end = run.wait(60)
        assert end is not None and end.ended_by == "done", end
        assert machine.position == plan_program(parsed[1], SCURVE, (0, 0, 0)).end
    emu.stop()
    assert run.state is JobState.DONE and JobState.RESUMING not in run.states.history
    assert run.plan.base.moves == 40
    segments = list(run.plan.segments.segments())
    assert any(isinstance(s, CubicSegment) for s in segments)
    assert_trace_is_prediction(trace, segments, axis_count=3)


def test_lines_given_after_the_end_was_sent_go_on_from_rest(start_emulator) -> None:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        head = "G21 G90 F1800\n" + zigzag(1, 3)
        whole = head + zigzag(4, 3)
        program = parse_gcode(head, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)
        items = parse_gcode(whole, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance).items
        run = machine.run_job(
            plan_program(program, CONFIG, machine.position), program, open_end=True
        )
        wait_until(lambda: run.progress.done >= run.progress.total - 3)  # the end was sent
        assert run.extend(items[len(program.items) :], 7)
        run.close()
        end = run.wait(60)
        assert end is not None and end.ended_by == "done", end
        planned = plan_program(
            parse_gcode(whole, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance),
            CONFIG,
            (0, 0, 0),
        )
        assert machine.position == planned.end == tuple(link.status().position[:3])
    emu.stop()
    assert run.state is JobState.DONE
    assert run.states.history[-3:] == [JobState.RESUMING, JobState.STREAMING, JobState.DONE]
