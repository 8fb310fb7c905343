"""A sender streaming a file through `quadstep grbl` by character counting, over the real emulator
ticking in real time: the lines that come while the job runs are planned onto what the board has not
been sent, so the machine does not come to rest between lines that do not ask for it; every target
is exact and the emulator's step trace is the host's prediction of the stream it was sent. Feed hold,
cycle start and a soft reset mid-stream."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving
from host_helpers import assert_trace_is_prediction, read_trace

from quadstep.config import load_config
from quadstep.kernel.engine_model import predict
from quadstep.grbl.server import PtyServer
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import JobRun, JobState, Machine
from quadstep.machine import job as job_module
from quadstep.machine import rebase as rebase_module
from quadstep.machine.motion import Motion
from quadstep.planner.program import LinearMove

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def spiral(chords: int, feed: float = 2400.0, dwell_at: int | None = None) -> list[str]:
    """A spiral of short chords (corners the look-ahead takes moving), optionally a dwell."""
    lines = ["G21 G90 G94", f"G1 F{feed:g}"]
    for k in range(1, chords + 1):
        angle, radius = k * 0.12, 2.0 + k * 0.02
        x, y = 30 + radius * math.cos(angle), 30 + radius * math.sin(angle)
        lines.append(f"X{x:.3f} Y{y:.3f}")
        if k == dwell_at:
            lines.append("G4 P0.05")
    return lines


class Door:
    """The front door over a timed emulator with a trace; the jobs the machine ran, recorded."""

    def __init__(self, machine: Machine, pty: PtyServer, trace: Path) -> None:
        self.machine = machine
        self.pty = pty
        self.trace = trace
        self.jobs: list[JobRun] = []
        run_job = machine.run_job

        def recorded(*args: object, **kwargs: object) -> JobRun:
            job = run_job(*args, **kwargs)  # type: ignore[arg-type]
            self.jobs.append(job)
            return job

        machine.run_job = recorded  # type: ignore[method-assign]

    def steps(self) -> tuple[int, ...]:
        return tuple(self.machine.link.status().position[:3])


@pytest.fixture
def door(start_emulator, tmp_path: Path) -> Iterator[Door]:
    trace = tmp_path / "trace.csv"
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14, trace=trace)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            yield Door(machine, pty, trace)
    emu.stop()


def client(door: Door) -> GrblClient:
    grbl = GrblClient(str(door.pty.path))
    grbl.wait_banner()
    return grbl


def idle(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def file_end(lines: list[str], tmp_path: Path) -> tuple[int, ...]:
    path = tmp_path / "stream.nc"
    path.write_text("\n".join(lines) + "\n")
    return load_job(path, CONFIG, (0, 0, 0)).plan.end


def rests(job: JobRun) -> list[int]:
    """The segment boundaries of the job's stream where every axis is at rest (not the end)."""
    arrays = job.plan.base.segments.numpy()
    vn = np.abs(arrays["vn"][:-1]).sum(axis=1)
    return [int(i) for i in np.flatnonzero(vn == 0)]


def check_exact(door: Door, job: JobRun) -> None:
    """The trace is the prediction of the stream sent, and every move ends on its target."""
    trace = read_trace(door.trace)
    assert np.array_equal(trace, predict(list(job.plan.segments.segments()), axis_count=3).steps)
    base = job.plan.base
    ends = np.cumsum(base.segments.numpy()["n"], dtype=np.int64)[np.asarray(base.move_ends) - 1]
    assert job.program is not None
    targets, here = [], (0, 0, 0)
    for item in job.program.items:
        if isinstance(item, LinearMove) and CONFIG.to_steps(item.target) != here:
            here = CONFIG.to_steps(item.target)
            targets.append(here)
    assert len(targets) == len(ends)
    for tick, target in zip(ends, targets):
        done = trace[trace[:, 0] <= tick]
        assert tuple(int(done[done[:, 1] == a, 2].sum()) for a in range(3)) == target


@pytest.mark.realtime
def test_a_streamed_file_runs_as_one_job_without_a_stop_and_lands_exactly(
    door: Door, tmp_path: Path
) -> None:
    lines = spiral(240)
    with client(door) as grbl:
        assert grbl.stream_counting(lines) == ["ok"] * len(lines)
        grbl.wait_status(idle)
    assert door.steps() == file_end(lines, tmp_path)
    assert len(door.jobs) == 1  # every line came while the job ran: added to it
    job = door.jobs[0]
    assert job.state is JobState.DONE
    assert JobState.RESUMING not in job.states.history and job.states.starvations == 0
    assert len(job.plan.base) != len(job.plan.base.move_ends) and rests(job) == []
    check_exact(door, job)


def stall_once(monkeypatch: pytest.MonkeyPatch, frame: int, seconds: float) -> None:
    """The host stops streaming for `seconds` before its `frame`-th frame (a busy computer), so the
    board runs dry and brakes by itself."""
    wait_for_room, frames = Motion._wait_for_room, [0]

    def stalled(motion: Motion, *args, **kwargs):
        frames[0] += 1
        if frames[0] == frame:
            time.sleep(seconds)
        return wait_for_room(motion, *args, **kwargs)

    monkeypatch.setattr(Motion, "_wait_for_room", stalled)


@pytest.mark.realtime
@pytest.mark.parametrize("stalled", [False, True], ids=["steady", "host-stalls"])
def test_a_long_stream_lets_go_of_what_ran_and_lands_exactly(
    door: Door, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, stalled: bool
) -> None:
    """The running job lets go of what the board has run (machine/rebase.py, here every 40
    segments): what was sent is every plan in turn, and the spiral ends on its last target, also
    where the host stalls mid-stream and the board brakes by itself."""
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 40)
    if stalled:
        stall_once(monkeypatch, frame=40, seconds=2.0)
    sent: list = []  # what ran, in order: what each plan let go of, each leg run to its end
    let_go, next_leg = job_module.rebased, JobRun._next_leg
    rebases = []

    def recorded(plan, at):
        rebases.append(at.index)
        sent.extend(plan.segments.segments(0, at.index))
        return let_go(plan, at)

    def leg_ran(run: JobRun, here: tuple[int, ...]):  # on a busy computer: on from rest
        if run.states.history[-2:] == [JobState.STREAMING, JobState.RESUMING]:
            sent.extend(run.plan.segments.segments())  # the leg ran to its end, then lines came
        elif run.states.history[-2:] == [JobState.STARVED, JobState.RESUMING]:
            sent.extend(run.plan.segments.segments(0, run._offset))  # what ran before it braked
        return next_leg(run, here)

    monkeypatch.setattr(job_module, "rebased", recorded)
    monkeypatch.setattr(JobRun, "_next_leg", leg_ran)
    lines = spiral(400)
    with client(door) as grbl:
        assert grbl.stream_counting(lines) == ["ok"] * len(lines)
        grbl.wait_status(idle)
    assert door.steps() == file_end(lines, tmp_path)
    (job,) = door.jobs
    assert job.state is JobState.DONE
    assert rebases and len(sent) >= 40  # it let go of what ran
    assert job.progress.done == job.progress.total == len(sent) + len(job.plan)
    sent.extend(job.plan.segments.segments())
    if stalled:  # the stall made the board brake; a busy machine may make it brake again
        assert job.states.starvations >= 1
    if JobState.STARVED not in job.states.history:  # the board never braked by itself
        assert_trace_is_prediction(door.trace, sent, axis_count=3)


@pytest.mark.realtime
def test_a_dwell_in_the_stream_is_the_only_rest(door: Door, tmp_path: Path) -> None:
    lines = spiral(200, dwell_at=150)
    with client(door) as grbl:
        assert grbl.stream_counting(lines) == ["ok"] * len(lines)
        grbl.wait_status(idle)
    assert door.steps() == file_end(lines, tmp_path)
    assert len(door.jobs) == 1
    job = door.jobs[0]
    arrays = job.plan.base.segments.numpy()
    still = np.flatnonzero(
        (np.abs(arrays["v0"]).sum(axis=1) + np.abs(arrays["vn"]).sum(axis=1)) == 0
    )
    assert int(arrays["n"][still].sum()) == round(0.05 * CONFIG.tick_hz)  # the dwell, no more
    assert rests(job) == [int(still[0]) - 1, *(int(i) for i in still)]  # into it, through it
    check_exact(door, job)


def stream_in_thread(grbl: GrblClient, lines: list[str]) -> threading.Thread:
    answers: list[str] = []
    thread = threading.Thread(target=lambda: answers.extend(grbl.stream_counting(lines)))
    thread.start()
    return thread


def test_feed_hold_and_cycle_start_mid_stream(door: Door, tmp_path: Path) -> None:
    lines = spiral(240)
    with client(door) as grbl:
        sending = stream_in_thread(grbl, lines)
        grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[1] > 20)
        grbl.realtime(ord("!"))
        held = grbl.wait_status(lambda r: r.startswith("<Hold:0"))
        assert mpos(grbl.status()) == mpos(held)  # at rest while held
        grbl.realtime(ord("~"))
        sending.join(timeout=60)
        assert not sending.is_alive()
        grbl.wait_status(idle)
    assert door.steps() == file_end(lines, tmp_path)
    assert all(job.state is JobState.DONE for job in door.jobs)
    assert JobState.HELD in door.jobs[0].states.history


def test_soft_reset_mid_stream_drops_the_rest_and_unlock_goes_on(door: Door) -> None:
    lines = spiral(240)
    with client(door) as grbl:
        # answered as they are queued: the job runs on with lines waiting to be added
        assert grbl.stream_counting(lines) == ["ok"] * len(lines)
        grbl.realtime(0x18)
        said = grbl.expect_other(lambda line: line.startswith("Grbl 1.1h"))
        assert "ALARM:3" in said
        report = grbl.wait_status(lambda r: r.startswith("<Alarm"))
        stopped = door.steps()
        assert mpos(report) == tuple(round(x, 3) for x in CONFIG.to_mm(stopped))
        assert door.jobs[0].state is JobState.STOPPED
        assert grbl.command("$X")[1] == "ok"
        assert grbl.command("G0 X0 Y0")[1] == "ok"
        grbl.wait_status(idle)
        assert door.steps() == (0, 0, 0)
