"""The emergency stop's line in the TUI's log names the carriage's steps, as every other position it
shows: the board's count less the backlash take-ups (docs/BACKLASH.md), not the motors' own count."""

from __future__ import annotations

import copy
import re
from pathlib import Path

from quadstep.config import parse_config
from quadstep.machine import state_path
from quadstep.tui import QuadstepApp, Session, Target
from tui_helpers import MACHINE, log_text, open_job, until


async def test_a_stop_mid_job_names_the_carriage_position(emulator_binary: Path, tmp_path: Path) -> None:
    settings = copy.deepcopy(MACHINE)
    settings["axes"][0]["backlash"] = {"mm": 0.5}  # 40 steps: a take-up at each reversal of X
    machine = parse_config(settings, "test machine")
    job = tmp_path / "there-and-back.gcode"
    job.write_text("G21 G90\nG1 X10 F600\nG1 X2 F60\n")  # back to 2 at 1 mm/s: stopped mid-way
    session = Session(Target(emulator=True, emulator_options={"binary": emulator_binary}), machine,
                      state_file=state_path(None))
    app = QuadstepApp(session, job_path=str(job), poll_interval=0.05)
    async with app.run_test(size=(100, 32)) as pilot:
        await until(pilot, lambda: session.connected and app.machine.snapshot is not None, what="connection")
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.line == 3,
                    what="the way back to run")
        begun = app.machine.job.progress.done
        await until(pilot, lambda: app.machine.job.progress.done > begun + 20, what="the take-up done")
        await pilot.press("ctrl+x")  # the emergency key: STOP, no deceleration
        await until(pilot, lambda: "STOP: stopped at once at steps" in log_text(app), what="the stop")
        found = re.search(r"STOP: stopped at once at steps \[([-\d, ]+)\]", log_text(app))
        assert found is not None
        shown = [int(n) for n in found.group(1).split(",")]
        assert session.machine is not None
        carriage, motor = list(session.machine.position), list(session.machine.motor_position)
    assert shown == carriage
    assert shown[0] - motor[0] == 40  # the motor turned the dead band more at the reversal to −X
    assert 2 * 80 < shown[0] < 10 * 80  # mid-way back
