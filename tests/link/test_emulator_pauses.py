"""The emulator's own process paused (a loaded computer): a board never stops and reads the host's
frames all along, so the emulator, finding itself behind its clock, stands still for the pause
rather than running its queue dry without reading the line (firmware/native/README.md, Time)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest
from host_helpers import assert_trace_is_prediction

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.planner.plan import plan_program

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
ZIGZAG = "G21 G90 F1800\n" + "".join(f"G1 X{2 * k} Y{10 + k % 2}\n" for k in range(1, 60))


@pytest.mark.realtime
def test_a_paused_emulator_stands_still_instead_of_running_dry(start_emulator, tmp_path: Path) -> None:
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    program = parse_gcode(ZIGZAG, CONFIG.axis_names, (0.0,) * 3, CONFIG.arc_tolerance)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        plan = plan_program(program, CONFIG, machine.position)
        run = machine.run_job(plan, program)
        for _ in range(2):  # 0.6 s each: longer than the 14 segments queued last
            time.sleep(1.0)
            os.kill(emu.pid, signal.SIGSTOP)
            time.sleep(0.6)
            os.kill(emu.pid, signal.SIGCONT)
        end = run.wait(60)
        assert end is not None and end.ended_by == "done", end
    summary = emu.stop()
    assert summary["stalls"] >= 2  # it noticed each pause
    assert JobState.STARVED not in run.states.history
    assert [summary[f"position_{a}"] for a in range(3)] == list(plan.end)
    assert_trace_is_prediction(trace, plan.segments.segments(), axis_count=3)
