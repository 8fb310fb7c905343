"""The TUI driven by Textual's pilot against the real emulator on a real pty."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from quadstep.jog import JogMode, JogSettings
from quadstep.machine import load_state, state_path
from quadstep.protocol import State
from quadstep.tui import QuadstepApp, Session, Target
from quadstep.tui.help import HelpScreen
from tui_helpers import FAST_RELEASE, HELD_UNTIL_STOPPED, hold_key, log_text, read_holds, send_key, until, open_job


def make_app(
    machine: MachineConfig, emulator_binary: Path, *, free: bool, settings: JogSettings | None = None,
    events: Path | None = None, job_path: str = "", queue: int | None = None, trace: Path | None = None,
) -> QuadstepApp:
    options: dict[str, object] = {"free": free, "binary": emulator_binary}
    if queue is not None:
        options["queue"] = queue
    if trace is not None:
        options["trace"] = trace
    if events is not None:
        options["extra_args"] = ("--events", str(events))
    session = Session(Target(emulator=True, emulator_options=options), machine, settings,
                      state_file=state_path(None))
    return QuadstepApp(session, job_path=job_path, poll_interval=0.05)


def positions(app: QuadstepApp) -> tuple[int, ...]:
    machine = app.session.machine
    assert machine is not None
    return tuple(machine.status().position[:3])


async def connected(pilot, app: QuadstepApp) -> None:  # noqa: ANN001
    await until(pilot, lambda: app.session.connected and app.machine.snapshot is not None, what="connection")


async def shown(pilot, app: QuadstepApp, expected: tuple[int, ...], timeout: float = 10.0) -> None:  # noqa: ANN001
    """Until the screen's latest status shows the machine at rest at `expected`."""
    def at_rest() -> bool:
        s = app.machine.snapshot
        jogger = app.session.jogger
        return (s is not None and tuple(s.status.position[:3]) == expected and s.status.state == State.IDLE
                and s.feed == 0 and jogger is not None and not jogger.busy)

    await until(pilot, at_rest, timeout, what=f"position {expected}")


async def test_jog_keys_move_exactly_the_preset_distances(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await pilot.press("right", "right", "up", "pagedown")  # 1 mm each (the default preset)
        await shown(pilot, app, (160, 80, -400))
        await pilot.press("2", "left")  # 0.1 mm
        await shown(pilot, app, (152, 80, -400))
        await pilot.press("4", "right_square_bracket", "down", "pageup")  # 10 mm: X/Y by 4, Z by ]
        await pilot.press("1", "left", "left", "left")  # 0.01 mm × 3 from 1.9 mm: 1.87 mm = 149.6 steps
        await shown(pilot, app, (150, 0, 0))
        assert positions(app) == (150, 0, 0)
        # Y- by 10 mm from 1 mm and Z+ by 10 mm from -1 mm stop at the soft limits (0)
        text = log_text(app)
        assert "Y-: stops at the soft limit travel_min = 0.000 mm" in text
        assert "Z+: stops at the soft limit travel_max = 0.000 mm" in text


async def test_continuous_jog_stops_when_the_key_repeats_stop(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    events = tmp_path / "events.csv"
    app = make_app(machine, emulator_binary, free=False, settings=FAST_RELEASE, events=events)
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await pilot.press("c")
        jogger = app.session.jogger
        assert jogger is not None and jogger.mode == JogMode.CONTINUOUS
        await hold_key(app, "right", 0.6)
        await until(pilot, lambda: jogger.last_result is not None and not jogger.busy, what="the jog to end")
        result = jogger.last_result
        assert result is not None and result.end is not None
        assert result.end.ended_by == "release" and result.end.held
        status = app.session.machine.status()  # type: ignore[union-attr]
        assert status.state == State.IDLE and status.queue_fill == 0
        assert 0 < status.position[0] < 3200
        assert status.position[0] == result.position[0]
        # the board logged the deceleration the HOLD started
        assert [tick for tick, _ in read_holds(events)] == [result.end.hold_tick]
        await until(pilot, lambda: "release: decelerated to rest (HOLD)" in log_text(app), what="the message")


async def test_space_stops_a_continuous_jog_with_hold(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=False, settings=HELD_UNTIL_STOPPED)
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        app.session.releases_reported()  # a kitty terminal: one press jogs until the stop key
        await pilot.press("c")
        send_key(app, "up")
        jogger = app.session.jogger
        assert jogger is not None
        await until(pilot, lambda: jogger.busy and positions(app)[1] > 0, what="the jog to move")
        send_key(app, "space", " ")
        await until(pilot, lambda: jogger.last_result is not None and not jogger.busy, what="the jog to end")
        result = jogger.last_result
        assert result is not None and result.end is not None
        assert result.end.ended_by == "stop" and result.end.held
        assert 0 < positions(app)[1] < 3200


async def test_zero_keys_set_the_work_offset_and_leave_machine_coordinates_alone(
    machine: MachineConfig, emulator_binary: Path
) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await pilot.press("right", "up", "up", "pagedown", "pagedown")
        await shown(pilot, app, (80, 160, -800))
        await pilot.press("x")
        await until(pilot, lambda: "zeroed X in G54" in log_text(app), what="zeroing X")
        await pilot.press("0")
        await until(pilot, lambda: "zeroed X, Y, Z in G54" in log_text(app), what="zeroing every axis")
        snapshot_ok = lambda: (app.machine.snapshot is not None and app.machine.snapshot.work_mm == (0.0, 0.0, 0.0)
                               and app.machine.snapshot.position_mm == (1.0, 2.0, -2.0))  # noqa: E731
        await until(pilot, snapshot_ok, what="work 0 at machine (1, 2, -2) mm")
        assert positions(app) == (80, 160, -800)  # the steps are untouched
        # Z zeroed 2 mm down can still be raised back to its soft limit (travel_max = 0, machine), and X
        # can go on down to its machine travel_min: the limits did not move with the zero.
        await pilot.press("pageup", "pageup", "pageup", "left", "left")
        await shown(pilot, app, (0, 160, 0))
        assert "Z+: stops at the soft limit travel_max = 0.000 mm" in log_text(app)
        assert app.machine.snapshot.work_mm == (-1.0, 0.0, 2.0)  # type: ignore[union-attr]
        stored = load_state(app.session.state_file)  # type: ignore[arg-type]
        assert stored.offsets[0] == {"X": 1.0, "Y": 2.0, "Z": -2.0}


async def test_a_job_runs_from_the_tui_to_its_end(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "square.gcode"
    job.write_text("G21 G90\nG1 X10 Y0 F1200\nG1 X10 Y10\nG1 X0 Y10\nG1 X2.5 Y2.5\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await open_job(pilot)
        await until(pilot, lambda: "square.gcode: done" in log_text(app), what="the job to finish")
        await shown(pilot, app, (200, 200, 0))


async def test_a_job_waits_at_m0_until_g(machine: MachineConfig, emulator_binary: Path, tmp_path: Path) -> None:
    job = tmp_path / "pause.gcode"
    job.write_text("G1 X5 F1200\nM0\nG1 X10\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.paused_at == 2,
                    what="the pause at line 2")
        assert positions(app) == (400, 0, 0)
        await pilot.press("g")
        await until(pilot, lambda: "pause.gcode: done" in log_text(app), what="the job to finish")
        assert positions(app) == (800, 0, 0)


async def test_a_running_job_holds_with_space_and_stops_with_esc(machine: MachineConfig, emulator_binary: Path,
                                                                 tmp_path: Path) -> None:
    job = tmp_path / "long.gcode"
    job.write_text("G1 X30 F60\nG1 X0\n")  # 1 mm/s: the stop lands mid-move even on a loaded machine
    app = make_app(machine, emulator_binary, free=False, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None, what="the job to start")
        send_key(app, "right")  # jogging is refused while a job runs
        await until(pilot, lambda: "jog: a job is running" in log_text(app) and positions(app)[0] > 0,
                    what="the refusal, and the job under way")
        send_key(app, "space", " ")  # a feed hold: at rest, the rest of the job kept
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.held, what="the feed hold")
        assert "jog: a job is running (Space holds it, Esc stops it)" in log_text(app)
        status = app.session.machine.status()  # type: ignore[union-attr]
        assert status.state == State.IDLE and status.queue_fill == 0
        held_at = status.position[0]
        assert 0 < held_at < 2400
        send_key(app, "space", " ")  # resume: it moves on from where it rests
        await until(pilot, lambda: app.session.machine.status().position[0] > held_at,  # type: ignore[union-attr]
                    what="the job to move on")
        send_key(app, "escape")
        await until(pilot, lambda: "long.gcode: stopped near line 1 (HOLD)" in log_text(app), what="the stop")
        assert app.machine.job is None


async def test_a_bad_job_is_refused_and_nothing_moves(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "far.gcode"
    job.write_text("G1 X10 F600\nG1 X50\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await pilot.press("o", "enter")  # refused: never shown
        await until(pilot, lambda: "job not started" in log_text(app), what="the refusal")
        assert "line 2: X 50.000 mm is outside the travel 0.000 … 40.000 mm" in log_text(app)
        assert positions(app) == (0, 0, 0)
        assert app.session.machine.status().motion_ticks == 0  # type: ignore[union-attr]


async def test_a_lost_connection_shows_and_reconnects(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        emulator = app.session.emulator
        assert emulator is not None
        emulator.stop()  # the board goes away
        banner = app.machine.query_one("#banner")
        await until(pilot, lambda: banner.display, what="the loss to show")
        assert app.session.lost is not None
        assert "DISCONNECTED" in str(banner.render())
        await pilot.press("right")
        assert "jog: not connected (Ctrl+R reconnects)" in log_text(app)
        await pilot.press("ctrl+r")
        await connected(pilot, app)
        assert not banner.display
        await pilot.press("right")
        await shown(pilot, app, (80, 0, 0))


async def test_help_lists_the_keys_and_keys_do_not_jog_under_it(
    machine: MachineConfig, emulator_binary: Path
) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(100, 40)) as pilot:
        await connected(pilot, app)
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        await pilot.press("right", "up")
        await pilot.pause(0.2)
        assert positions(app) == (0, 0, 0)
        await pilot.press("escape")
        assert app.screen is app.machine


async def test_quitting_during_a_job_brings_the_machine_to_rest(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "long.gcode"
    job.write_text("G1 X30 F60\n")  # 30 s: the quit lands mid-job even on a loaded machine
    app = make_app(machine, emulator_binary, free=False, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        emulator = app.session.emulator
        assert emulator is not None
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and positions(app)[0] > 0,
                    what="the job under way")
        await pilot.press("ctrl+q")
    # HOLD before the link closed: at rest, no underrun from a host that left mid-job
    assert emulator.summary is not None
    assert emulator.summary["state"] == "IDLE" and emulator.summary["alarm"] == "NONE"
    assert 0 < int(emulator.summary["position_0"]) < 2400


async def test_a_job_runs_in_the_work_coordinates_the_zero_keys_set(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "work.gcode"
    job.write_text("G1 X5 Y0 F1200\nG10 L20 P2 X0\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await pilot.press("right", "right", "up")  # machine X 2 mm, Y 1 mm
        await shown(pilot, app, (160, 80, 0))
        await pilot.press("0")
        await until(pilot, lambda: "zeroed X, Y, Z in G54" in log_text(app), what="zeroing")
        await open_job(pilot)
        await until(pilot, lambda: "work.gcode: done" in log_text(app), what="the job to finish")
        await shown(pilot, app, (560, 80, 0))  # work X5 Y0 is machine X 7, Y 1
        kept = load_state(app.session.state_file)  # type: ignore[arg-type]
        assert kept.offsets[1] == {"X": 7.0}  # the job's G10 L20 P2 X0 is kept: it completed


async def test_a_job_stopped_at_its_pause_resumes_with_r(machine: MachineConfig, emulator_binary: Path,
                                                          tmp_path: Path) -> None:
    job = tmp_path / "pause.gcode"
    job.write_text("G1 X5 F1200\nM0\nG1 X10\n")
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(100, 32)) as pilot:
        await connected(pilot, app)
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.paused_at == 2,
                    what="the pause at line 2")
        await pilot.press("escape")
        await until(pilot, lambda: "pause.gcode: stopped" in log_text(app), what="the stop")
        await pilot.press("R")
        await until(pilot, lambda: "resuming" in log_text(app), what="the resume")
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.paused_at == 2,
                    what="the pause offered again")
        assert positions(app) == (400, 0, 0)
        await pilot.press("g")
        await until(pilot, lambda: "pause.gcode: done" in log_text(app), what="the job to finish")
        assert positions(app) == (800, 0, 0)
        await pilot.press("R")
        await until(pilot, lambda: "no stopped job is kept" in log_text(app), what="nothing left to resume")
