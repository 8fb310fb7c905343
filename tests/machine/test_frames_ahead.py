"""A motion of short segments sends frames beyond the board's queue while what it has queued lasts
less than AHEAD_S: they wait in the link's window and go out as the board frees slots, and the job
still lands on every step the plan gives."""

from __future__ import annotations

import math
import threading
from pathlib import Path

import pytest
from host_helpers import assert_trace_is_prediction, read_trace

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.machine.motion import AHEAD_S, AHEAD_SLOTS, fits_queue
from quadstep.planner.plan import plan_program
from quadstep.protocol import IdentifyReply

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")


def uno(queue: int = 14, tick_hz: int = 32000) -> IdentifyReply:
    return IdentifyReply.model_construct(queue_capacity=queue, tick_hz=tick_hz)


def test_frames_go_beyond_the_queue_only_while_the_motion_queued_is_short() -> None:
    board = uno()
    short = int(AHEAD_S * board.tick_hz) - 1  # ticks: just under AHEAD_S
    assert fits_queue(13, 10**6, board)  # into the queue, however long
    assert fits_queue(14, short, board) and fits_queue(14 + AHEAD_SLOTS - 1, short, board)
    assert not fits_queue(14, short + 1, board)  # as much queued as AHEAD_S: the queue alone
    assert not fits_queue(14 + AHEAD_SLOTS, 0, board)  # the window's share is bounded too


def chords(count: int, length_mm: float) -> str:
    radius, lines = 20.0, ["G21 G90 G94", "G0 X70 Y50", "G1 F2400"]
    for k in range(1, count + 1):
        angle = k * length_mm / radius
        lines.append(f"X{50 + radius * math.cos(angle):.4f} Y{50 + radius * math.sin(angle):.4f}")
    return "\n".join(lines) + "\n"


@pytest.mark.realtime
def test_a_job_of_short_chords_keeps_frames_waiting_beyond_an_unos_queue(
    start_emulator, tmp_path: Path
) -> None:
    """0.05 mm chords at 40 mm/s (1.3 ms each) on an Uno's 14 slots in real time: the link's window
    holds more unacknowledged frames than the board has slots, and the steps are the plan's (where a
    computer busy enough let the board run dry on the way, it braked past what it was sent and the job
    came back from there: then the steps add up to the plan's end)."""
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14, trace=tmp_path / "trace.csv")
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        program = parse_gcode(chords(600, 0.05), CONFIG.axis_names, (0, 0, 0), CONFIG.arc_tolerance)
        plan = plan_program(program, CONFIG, machine.position)
        most, done = [0], threading.Event()

        def watch() -> None:
            while not done.wait(0.001):
                most[0] = max(most[0], link.in_flight)

        watcher = threading.Thread(target=watch)
        watcher.start()
        try:
            run = machine.run_job(plan, program)
            end = run.wait(60)
        finally:
            done.set()
            watcher.join()
        assert end is not None and end.ended_by == "done", end
        assert tuple(link.status().position[:3]) == plan.end
    assert most[0] > 14
    emu.stop()
    if JobState.STARVED in run.states.history:
        got = read_trace(emu.trace)
        assert [int(got[got[:, 1] == axis, 2].sum()) for axis in range(3)] == list(plan.end)
        return
    steps = plan.segments.segments()
    assert_trace_is_prediction(emu.trace, steps, axis_count=3)  # type: ignore[arg-type]
