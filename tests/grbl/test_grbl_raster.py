"""A LightBurn-style grayscale raster (a `G1 X… S…` a pixel, rows both ways, M4) streamed through
`quadstep grbl` by character counting, over the real emulator ticking in real time: its rows go out
as RASTER lines in jobs of their own, planned whole, so the board never runs dry; every step is the
host's prediction of what it was sent and the machine ends where the file does."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving
from host_helpers import assert_trace_is_prediction
from laser_raster import raster_gcode, record_jobs

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import JobRun, JobState, Machine
from quadstep.protocol.raster import RasterLine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "laser-uno.toml")


@pytest.fixture
def door(start_emulator, tmp_path: Path) -> Iterator[tuple[Machine, Path, Path, list[JobRun]]]:  # noqa: ANN001
    trace = tmp_path / "trace.csv"
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14, trace=trace)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        jobs = record_jobs(machine)
        with serving(machine) as pty:
            yield machine, pty.path, trace, jobs
    emu.stop()


@pytest.mark.realtime
@pytest.mark.parametrize("relative", [False, True], ids=["absolute", "G91-rows"])
def test_a_streamed_raster_goes_out_as_raster_lines_and_never_runs_dry(door, tmp_path: Path, relative: bool) -> None:  # noqa: ANN001
    machine, path, trace, jobs = door
    # 1,300 lines: more than the queue takes before a job starts; LightBurn writes its rows in G91
    lines = raster_gcode(rows=8, pixels=160, relative=relative)
    before = dict(machine.link.stats.as_dict())
    with GrblClient(str(path)) as grbl:
        grbl.wait_banner()
        assert grbl.stream_counting(lines) == ["ok"] * len(lines)
        grbl.wait_status(lambda report: report_fields(report)["state"] == "Idle")
    after = machine.link.stats.as_dict()
    file = tmp_path / "raster.nc"
    file.write_text("\n".join(lines) + "\n")
    assert tuple(machine.link.status().position[:3]) == load_job(file, CONFIG, (0, 0, 0)).plan.end
    assert len(jobs) >= 2 and all(job.state is JobState.DONE for job in jobs)
    assert all(job.states.starvations == 0 for job in jobs)
    sent = [segment for job in jobs for segment in job.plan.segments.segments()]
    burned = sum(len(s.raster.power) for s in sent if isinstance(s, RasterLine))
    assert burned >= 8 * 160  # every pixel in a RASTER line (a row's lines may hold its ramps' ends)
    frames = after["frames_sent"] - before["frames_sent"]
    assert after["retransmits"] - before["retransmits"] <= 0.01 * frames
    sent_bytes = after["bytes_sent"] - before["bytes_sent"]
    print(f"{len(jobs)} jobs, {frames} frames, {sent_bytes / burned:.2f} B a pixel")
    assert sent_bytes <= 5 * 8 * 160  # as moves, a segment and an OUTPUTS a pixel: about 50 B
    assert_trace_is_prediction(trace, sent, axis_count=3)


@pytest.mark.realtime
def test_a_feed_hold_inside_a_streamed_raster_goes_on_from_where_it_stopped(door, tmp_path: Path) -> None:  # noqa: ANN001
    """`!` while a row burns, `~` a moment later: the row goes on, and the machine ends where the file
    does."""
    machine, path, _, jobs = door
    lines = raster_gcode(rows=6, pixels=160)
    with GrblClient(str(path)) as grbl:
        grbl.wait_banner()
        answers: list[str] = []
        sending = threading.Thread(target=lambda: answers.extend(grbl.stream_counting(lines)))
        sending.start()
        grbl.wait_status(lambda report: report.startswith("<Run") and mpos(report)[1] > 10.25)
        grbl.realtime(ord("!"))
        held = grbl.wait_status(lambda report: report.startswith("<Hold:0"))
        assert mpos(grbl.status()) == mpos(held)  # at rest while held
        grbl.realtime(ord("~"))
        sending.join(timeout=60)
        assert not sending.is_alive() and answers == ["ok"] * len(lines)
        grbl.wait_status(lambda report: report_fields(report)["state"] == "Idle")
    file = tmp_path / "raster.nc"
    file.write_text("\n".join(lines) + "\n")
    assert tuple(machine.link.status().position[:3]) == load_job(file, CONFIG, (0, 0, 0)).plan.end
    assert all(job.state is JobState.DONE for job in jobs)
    assert any(JobState.HELD in job.states.history for job in jobs)
