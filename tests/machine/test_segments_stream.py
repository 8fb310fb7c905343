"""A job streams as SEGMENTS frames (PROTOCOL.md §5.2): several chained segments a frame, far fewer frames and
bytes than segments, and the board makes exactly the steps the plan predicts, on an Uno-sized queue."""

from __future__ import annotations

from pathlib import Path

from host_helpers import assert_trace_is_prediction

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.protocol import Capability
from quadstep.protocol.frame_choice import SINGLE_FRAMES

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
