"""Faults on the line and at either end, with the real emulator behind a real byte-level proxy (byte_faults.py):
a job through a line that damages 1 % of the bytes both ways runs exactly as without faults; a soak at 0.1 %;
a board that goes silent, on a pseudo-terminal and on TCP, is noticed within 2 s whatever the window's state."""

from __future__ import annotations

import os
import resource
import signal
import time
from pathlib import Path

import pytest
from byte_faults import FaultyLine
from fault_jobs import engraving
from host_helpers import assert_trace_is_prediction

from quadstep.config import MachineConfig, load_config
from quadstep.job import load_job
from quadstep.link import BoardSilent, Link
from quadstep.machine import Machine
from quadstep.protocol import CubicSegment, Segment
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def router() -> MachineConfig:
    return load_config(REPO / "examples" / "router-uno.toml")


def run_through(line_p: float, emu, config: MachineConfig, job_path: Path, seed: int = 7):
    with FaultyLine(emu.url, line_p, seed=seed) as line, Link.open(line.port) as link:
        machine = Machine(link, config)
        job = load_job(job_path, config, machine.position)
        end = machine.run_job(job.plan).wait()
        stats = machine.stats.as_dict()
        machine.close()
    return job, end, stats, line


@pytest.mark.realtime
@pytest.mark.parametrize("jerk", [None, 20000.0], ids=["constant acceleration", "S-curve"])
def test_one_percent_of_the_bytes_damaged_both_ways_changes_nothing(start_emulator, router: MachineConfig,
                                                                     tmp_path: Path, jerk: float | None) -> None:
    """A real-time job (150 moves, about 2.5 s) through a line that flips, drops, doubles and inserts 1 % of the bytes
    in each direction: it completes, the step trace is the fault-free prediction tick for tick, and every segment
    ran exactly once; with max_jerk too (cubic segments, one a frame while the line is noisy)."""
    if jerk is not None:
        router = router.model_copy(update={"axes": [a.model_copy(update={"max_jerk": jerk}) for a in router.axes]})
    path = tmp_path / "job.gcode"
    path.write_text(engraving(150, size=10.0))
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=router.tick_hz, queue=14)
    job, end, stats, line = run_through(1e-2, emu, router, path)
    assert end is not None and end.ended_by == "done", end
    summary = emu.stop()
    assert line.faults > 20 and stats["retransmits"] > 0
    if jerk is not None:
        assert all(isinstance(s, CubicSegment) for s in job.plan.segments.segments(1))
    assert summary["segments_done"] == len(job.plan)
    assert summary["motion_ticks"] == job.plan.duration_ticks
    assert [summary[f"position_{a}"] for a in range(3)] == list(job.plan.end)
    assert_trace_is_prediction(trace, job.plan.segments.segments(), job.plan.start, axis_count=3)


def test_soak_at_a_tenth_of_a_percent(start_emulator, router: MachineConfig, tmp_path: Path) -> None:
    """A few thousand segments, free-running, through 0.1 % byte faults: exact, and the host's memory flat."""
    path = tmp_path / "job.gcode"
    path.write_text(engraving(1500))
    emu = start_emulator(free=True, axes=3, tick_hz=router.tick_hz, queue=14)
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    job, end, stats, line = run_through(1e-3, emu, router, path, seed=11)
    assert end is not None and end.ended_by == "done", end
    summary = emu.stop()
    assert summary["segments_done"] == len(job.plan) > 1500
    assert [summary[f"position_{a}"] for a in range(3)] == list(job.plan.end)
    assert line.faults > 0
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before < 50_000  # kB: flat, not growing


CRUISE = Segment(n=N_MAX, axes=(AxisMove(axis=0, direction=1, v0=D // 8, vn=D // 8, r=0),))


@pytest.mark.parametrize("tcp", [False, True], ids=["pty", "tcp"])
@pytest.mark.parametrize("window", ["full", "in flight"])
def test_a_silent_board_is_noticed_within_two_seconds(start_emulator, tcp: bool, window: str) -> None:
    """SIGSTOP the board with its queue full and nothing in flight (only a SPACE ack could open the window), or
    with frames in flight: BoardSilent in under 2 s, naming what the board last confirmed."""
    emu = start_emulator(tick_hz=20000, queue=4, extra_args=("--tcp", "0") if tcp else ())
    with Link.open(emu.url) as link:
        for _ in range(4):
            link.send(CRUISE)
        link.drain(timeout=5)
        os.kill(emu.pid, signal.SIGSTOP)
        try:
            start = time.monotonic()
            with pytest.raises(BoardSilent, match=r"last frame it confirmed was seq \d+; \d+ segments done"):
                if window == "in flight":
                    for _ in range(4):
                        link.send(Segment(n=10, axes=()), timeout=10)
                link.wait_idle(timeout=30)
            assert time.monotonic() - start < 2.0
        finally:
            os.kill(emu.pid, signal.SIGCONT)
