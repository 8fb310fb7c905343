"""A large G-code file checked whole in one pass (job_scan.py), then planned and sent a part at a time
(machine/file_feed.py) on the real emulator: it ends exactly on its last target, its trace is the
host's prediction of the stream as sent; and a file with a bad line far down is refused, line named,
before anything moves."""

from __future__ import annotations

from pathlib import Path

import pytest
from host_helpers import assert_trace_is_prediction

from quadstep.cli import _streamed, main
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.job_scan import GcodeParts, scan_job
from quadstep.link import Link
from quadstep.machine import JobRun, JobState, Machine
from quadstep.machine import job as job_module
from quadstep.machine import rebase as rebase_module
from quadstep.machine.file_feed import feed_file

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
LINES = 3_000  # 0.2 mm moves: 15 s of motion


def back_and_forth(lines: int, step: float = 0.05) -> str:
    """`lines` short G1 moves along X, turning at 0 and 100 mm, a little higher in Y each turn."""
    out, x, y, direction = ["G21 G90 F2400"], 0.0, 0.0, 1
    for _ in range(lines - 1):
        if not 0.0 <= x + direction * step <= 100.0:
            direction, y = -direction, y + 0.5
            out.append(f"G1 Y{y:.3f}")
            continue
        x += direction * step
        out.append(f"G1 X{x:.3f}")
    return "\n".join(out) + "\n"


@pytest.mark.realtime
@pytest.mark.slow
def test_a_streamed_file_ends_on_its_targets_as_predicted(
    start_emulator, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where the feed falls behind (a loaded computer), the machine comes to rest at the end of what
    it was given and the job goes on from there (a leg from rest, or a job after it); a long job
    lets go of what ran (machine/rebase.py): the stream as sent is every such leg's plan in turn."""
    job = tmp_path / "long.gcode"
    job.write_text(back_and_forth(LINES, 0.2))
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    # every leg that ran to its end, in order, as (stream, first, end): read once the job ran, as
    # building thousands of segments in the job's thread would hold it back while the board runs
    parts: list = []
    next_leg = JobRun._next_leg

    def leg_ran(run: JobRun, here: tuple[int, ...]):
        if run.states.history[-2:] == [JobState.STREAMING, JobState.RESUMING]:  # after a done
            parts.append((run.plan.segments, 0, len(run.plan.segments)))
        return next_leg(run, here)

    monkeypatch.setattr(JobRun, "_next_leg", leg_ran)
    let_go = job_module.rebased
    let_go_at: list[int] = []

    def let_go_of_what_ran(plan, at):  # a long job lets go of what ran: that part was sent
        let_go_at.append(at.index)
        parts.append((plan.segments, 0, at.index))
        return let_go(plan, at)

    monkeypatch.setattr(job_module, "rebased", let_go_of_what_ran)
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 1000)  # a long job's, in a shorter one
    runs: list[JobRun] = []
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        scan = scan_job(job, CONFIG, machine.position)
        assert scan.lines == LINES and not scan.probes
        feed = feed_file(machine, GcodeParts(job, CONFIG, machine.position), on_run=runs.append)
        run: JobRun | None = feed.run
        while run is not None:
            end = run.wait(900)
            assert end is not None and end.ended_by == "done", end
            parts.append((run.plan.segments, 0, len(run.plan.segments)))
            run = feed.next_run(run)
        feed.stop()
        assert feed.error is None
        whole = load_job(job, CONFIG).plan
        assert machine.position == scan.end_steps == whole.end
        assert tuple(link.status().position[:3]) == whole.end
    emu.stop()
    for run in runs:
        assert run.state is JobState.DONE
        # the board never ran dry (braking by itself): what it ran is the stream as sent
        assert JobState.STARVED not in run.states.history
    assert len(let_go_at) >= 2  # it let go of what ran, more than once
    sent = [segment for stream, first, end in parts for segment in stream.segments(first, end)]
    assert_trace_is_prediction(trace, sent, axis_count=3)


@pytest.mark.parametrize(
    "bad, error",
    [
        ("G1 Y250", "line {n}: Y 250.000 mm is outside the travel 0.000 … 200.000 mm"),
        ("G1 X3O", "line {n}, column 6: 'O' has no number after it"),
    ],
)
def test_a_bad_line_far_down_moves_nothing(
    bad: str, error: str, start_emulator, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    job = tmp_path / "bad.gcode"
    lines = back_and_forth(30_000).splitlines()
    lines[29_000] = bad
    job.write_text("\n".join(lines) + "\n")
    assert job.stat().st_size > _streamed.STREAM_BYTES  # checked whole before it is streamed
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    code = main(["run", str(job), "--config", str(ROUTER), "--port", emu.url])
    _, err = capsys.readouterr()
    assert code == 1
    assert err == f"quadstep run: error: {job}: {error.format(n=29_001)}\n"
    with Link.open(emu.url) as link:
        status = link.status()
    assert (status.segments_done, status.motion_ticks, tuple(status.position[:3])) == (
        0,
        0,
        (0, 0, 0),
    )


def test_run_streams_a_large_file_to_its_end(
    start_emulator,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`quadstep run` of a file over STREAM_BYTES (here lowered): checked, streamed, exactly at its end."""
    monkeypatch.setattr(_streamed, "STREAM_BYTES", 1000)
    job = tmp_path / "streamed.gcode"
    job.write_text(back_and_forth(1500, 0.2) + "M2\nG1 X5\n")
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz)
    code = main(["run", str(job), "--config", str(ROUTER), "--port", emu.url])
    out, err = capsys.readouterr()
    assert code == 0, err
    whole = load_job(job, CONFIG).plan
    assert out.splitlines()[:2] == [
        "line 1501 ends the program (M2/M30): the 1 line after it is not run",
        f"{job}: 1501 lines, {whole.moves} moves; every target inside the travel; planned and sent a part "
        "at a time",
    ]
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    with Link.open(emu.url) as link:
        assert tuple(link.status().position[:3]) == whole.end
