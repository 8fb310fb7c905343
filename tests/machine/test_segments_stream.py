"""A job streams as SEGMENTS frames (PROTOCOL.md §5.2): several chained segments a frame, far fewer frames and
bytes than segments, and the board makes exactly the steps the plan predicts, on an Uno-sized queue."""

from __future__ import annotations

import time
from pathlib import Path

from host_helpers import assert_trace_is_prediction

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.kernel.motion import AxisMove
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.machine.motion import Motion
from quadstep.planner.segments import SegmentArrays
from quadstep.protocol import Capability, Segment
from quadstep.protocol.frame_choice import SINGLE_FRAMES
from quadstep.protocol.messages import queue_slots

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def test_a_job_goes_out_several_segments_a_frame_and_runs_exactly(start_emulator, tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        assert link.identity is not None and link.identity.capabilities & Capability.SEGMENTS
        job = load_job(REPO / "examples" / "demo.gcode", CONFIG, machine.position)
        before = dict(link.stats.as_dict())
        end = machine.run_job(job.plan).wait()
        after = link.stats.as_dict()
        machine.close()
    assert end is not None and end.ended_by == "done", end
    frames = after["frames_sent"] - before["frames_sent"]
    sent = after["bytes_sent"] - before["bytes_sent"]
    segments = len(job.plan)
    assert frames < segments / 3  # up to 7 a frame (keep-alives and STATUS polls count too)
    assert sent < job.wire_bytes(SINGLE_FRAMES) / 2  # against one SEGMENT a frame
    assert_trace_is_prediction(trace, job.plan.segments.segments(), list(job.plan.start), axis_count=3)
    summary = emu.stop()
    assert summary["segments_done"] == segments
    assert [summary[f"position_{a}"] for a in range(3)] == list(job.plan.end)


def test_a_host_that_fell_behind_catches_up_in_one_frame(start_emulator, tmp_path: Path) -> None:
    """Moves of 3.5 ms: 14 slots hold less than the 50 ms under which a motion sends little at a
    time. A frame holds no more than the board has queued before it and room for at once: a few
    as the queue fills, one a frame once full, and, after the host stalled for 20 ms (a busy
    computer) while the board ran on, what it ran in one frame."""
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=10_000, queue=14)
    ramp = [Segment(n=35, axes=(AxisMove(axis=0, direction=1, v0=v, vn=v + 40, r=0),)) for v in range(0, 1200, 40)]
    cruise = Segment(n=35, axes=(AxisMove(axis=0, direction=1, v0=1200, vn=1200, r=0),))
    stop = [Segment(n=35, axes=(AxisMove(axis=0, direction=1, v0=v + 40, vn=v, r=0),)) for v in range(1160, -1, -40)]
    plan = [*ramp, *[cruise] * 40, *stop]
    frames: list[int] = []  # segments a frame, in order
    with Link.open(emu.url) as link:
        send = link.send

        def sent(message, **options):  # noqa: ANN001, ANN202
            if queue_slots(message):
                frames.append(queue_slots(message))
                if len(frames) == 30:
                    time.sleep(0.02)  # the host stalls; the board runs on
            return send(message, **options)

        link.send = sent  # type: ignore[method-assign]
        end = Motion(link, SegmentArrays.of(plan, 3), (200, 200, 200)).start().wait(20)
        starved = link.stats.starvations
    assert end is not None and end.ended_by == "done", end
    assert sum(frames) == len(plan) and starved == 0
    assert frames[:2] == [1, 1] and max(frames[:8]) > 1  # no more than the board has queued
    assert max(frames[30:33]) >= 3  # 20 ms of the board's motion is five or six segments: at once
    assert_trace_is_prediction(trace, plan, axis_count=3)
