"""Every fault at full speed ends in a controlled stop with the position known: the host killed mid-job (the
firmware's watchdog), and the queue run dry (an underrun). Each stop is checked against the trace: every step
after the stop began is the one a hold at the configured decelerations makes (engine_model.predict_hold), so the
deceleration never exceeds the configured one; and the position the board reports at reconnect is exact."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from host_helpers import read_trace

from quadstep.config import load_config
from quadstep.kernel.engine_model import predict, predict_hold, predict_underrun
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.machine.motion import STARVED
from quadstep.machine.units import hold_decels
from quadstep.protocol import AlarmCode, HoldDone, Output, State

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
FAST = "G21 G90\nG0 X250 Y180\nG0 X0 Y0\n"  # rapids: seconds at full speed


def hold_ticks(events: Path) -> list[int]:
    return [int(line.split(",")[1]) for line in events.read_text().splitlines()[1:] if line.startswith("hold,")]


def kill_mid_job(job: Path, config: Path, url: str) -> None:
    """`quadstep run JOB` on the board at `url`, killed (SIGKILL, without a word to the board) a second after it
    began to stream."""
    cli = subprocess.Popen([sys.executable, "-m", "quadstep.cli", "run", str(job), "--config", str(config),
                            "--port", url], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL)
    try:
        assert cli.stdout is not None
        assert "planned" in cli.stdout.readline().decode()  # printed as the stream starts
        time.sleep(1.0)
        assert cli.poll() is None
    finally:
        os.kill(cli.pid, signal.SIGKILL)
        cli.wait()


def test_the_host_killed_at_full_speed_leaves_a_controlled_stop_and_an_exact_position(start_emulator,
                                                                                       tmp_path: Path) -> None:
    job = tmp_path / "fast.gcode"
    job.write_text(FAST)
    trace, events = tmp_path / "trace.csv", tmp_path / "events.csv"
    # A queue deeper than the watchdog's time (127 slots of 32 ms rapids), so the host's lookahead, not the
    # queue, bounds what is queued: the board still has motion when the watchdog fires. (A queue that holds
    # less than host_timeout of motion runs dry first: the same controlled stop, as UNDERRUN.)
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=127,
                         extra_args=("--events", str(events)))
    kill_mid_job(job, ROUTER, emu.url)  # well into the first rapid, at full speed
    deadline = time.monotonic() + 30
    while not hold_ticks(events):  # the watchdog's stop (nothing is sent before it: any frame would feed it)
        assert time.monotonic() < deadline, "the board never stopped on its own"
        time.sleep(0.05)
    with Link.open(emu.url) as link:
        deadline = time.monotonic() + 5
        while (status := link.status()).state == State.HOLDING:  # decelerating: about 80 ms
            assert time.monotonic() < deadline, "the board never came to rest"
        assert status.state == State.ALARM and status.alarm == AlarmCode.HOST_LOST
        at_rest = list(status.position[:3])
        link.stop()
    emu.stop()
    plan = load_job(job, CONFIG, (0, 0, 0)).plan
    (hold_tick,) = hold_ticks(events)
    stop = predict_hold(plan.segments.segments(), hold_tick, hold_decels(CONFIG), axis_count=3)
    assert stop.positions == at_rest
    moved = predict(plan.segments.segments(), axis_count=3).steps
    expected = np.concatenate([moved[moved[:, 0] <= hold_tick], stop.steps])
    steps = read_trace(trace)
    assert np.array_equal(steps, expected)
    assert len(stop.steps) > 100  # it was moving fast: a real deceleration, not a stop at speed
    assert status.motion_ticks == stop.motion_ticks


def test_an_underrun_at_full_speed_brakes_at_the_configured_deceleration(start_emulator, tmp_path: Path) -> None:
    """The stream stops halfway through a rapid (the host stops sending): the firmware brakes from the last
    segment's end at the machine's decelerations and rests STARVED, no alarm, at the exact position; the motion
    ends "starved" at once with that stop's hold_tick, and its HOLD leaves the board IDLE for what comes next."""
    job = tmp_path / "fast.gcode"
    job.write_text(FAST)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    plan = load_job(job, CONFIG, (0, 0, 0)).plan
    segments = list(plan.segments.segments())
    ticks = np.cumsum([s.n for s in segments])
    half = int(np.searchsorted(ticks, ticks[-1] // 4))  # mid-rapid, at full speed
    stop = predict_underrun(segments[:half], hold_decels(CONFIG), axis_count=3)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        end = machine.send_segments(segments[:half]).wait(timeout=60)
        done = link.last_report(HoldDone)
        assert end is not None and end.ended_by == STARVED and end.error is None
        assert end.held and end.hold_tick == ticks[half - 1] and end.segments_done == half
        assert done is not None and done.hold_tick == ticks[half - 1] and list(done.position[:3]) == stop.positions
        assert list(end.position) == stop.positions == list(machine.position)
        status = link.status()
        assert status.state == State.IDLE and status.alarm is None  # the motion's HOLD took it up again
        assert list(status.position[:3]) == stop.positions
        expected = np.concatenate([predict(segments[:half], axis_count=3).steps, stop.steps])
        assert np.array_equal(read_trace(trace), expected)  # the trace is written out at rest
        assert len(stop.steps) > 100
        # A new motion runs from there: a short move, from rest to rest.
        short = tmp_path / "short.gcode"
        short.write_text("G21 G91\nG0 X2 Y1\n")
        step = list(load_job(short, CONFIG, (0, 0, 0)).plan.segments.segments())
        again = machine.send_segments(step).wait(timeout=60)
        moved = predict(step, axis_count=3).positions
        assert again is not None and again.ended_by == "done" and again.segments_done == len(step)
        assert list(again.position) == [a + b for a, b in zip(stop.positions, moved)] != stop.positions
    emu.stop()


def test_a_laser_left_at_an_underrun_by_a_killed_host_is_switched_off(start_emulator, tmp_path: Path) -> None:
    """A laser job (M3: constant power, on at rest too) whose host is killed on an Uno's queue: the board runs
    dry and rests STARVED, which a live host takes up at once; silent past host_timeout, the host is gone, and
    the board switches every output off (ALARM HOST_LOST) instead of burning one spot."""
    config = tmp_path / "laser.toml"
    config.write_text(ROUTER.read_text() + "\n[spindle]\ns_max = 1000\nlaser = true\n")
    job = tmp_path / "laser.gcode"
    rows = "".join(f"G1 X45 Y{k}\nG1 X5 Y{k + 0.5}\n" for k in range(20))  # seconds of burning
    job.write_text("G21 G90\nM3 S800\nG1 X5 F1500\n" + rows + "M5\n")
    outputs = tmp_path / "outputs.csv"
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14, extra_args=("--outputs", str(outputs)))
    kill_mid_job(job, config, emu.url)
    time.sleep(4 * CONFIG.host_timeout)  # the queue's fraction of a second, then the watchdog
    with Link.open(emu.url) as link:
        status = link.status()  # asking changes nothing: no STOP, which would switch them off too
    emu.stop()
    assert status.state == State.ALARM and status.alarm == AlarmCode.HOST_LOST, status
    changes = [tuple(int(v) for v in row.split(",")) for row in outputs.read_text().splitlines()[1:]]
    assert any(pins & Output.ON for _, pins, _ in changes)  # the laser burned
    assert changes[-1][1:] == (0, 0)  # and is off at rest
