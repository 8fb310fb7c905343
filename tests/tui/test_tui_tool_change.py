"""A tool change (T M6) from the TUI: the job waits with the message, Z is jogged and zeroed on the new tool,
g goes on in the new offset — on the real emulator."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from test_tui import connected, make_app, positions, shown
from tui_helpers import log_text, until, open_job

JOB = "G21 G90 G54\nG0 X10 Y10\nG1 Z-5 F600\nG0 Z0\nT2 M6\nG0 X20\nG1 Z-5 F600\nG0 Z-1\nM30\n"


async def test_a_tool_change_waits_for_jog_zero_and_g(machine: MachineConfig, emulator_binary: Path,
                                                      tmp_path: Path) -> None:
    job = tmp_path / "tools.nc"
    job.write_text(JOB)
    app = make_app(machine, emulator_binary, free=True, job_path=str(job))
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await open_job(pilot)
        await until(pilot, lambda: "line 5: tool change to T2" in log_text(app), what="the tool change")
        assert positions(app) == (800, 800, 0)
        assert "PAUSED at 5: tool change to T2" in str(app.machine.query_one("#job-label").render())
        await pilot.press("pagedown")  # the new tool is 1 mm longer: down to the stock
        await until(pilot, lambda: positions(app) == (800, 800, -400) and not app.session.jogger.busy,
                    what="the jog at the pause")
        await pilot.press("z")
        await until(pilot, lambda: "zeroed Z in G54" in log_text(app), what="zeroing Z")
        await pilot.press("g")
        await until(pilot, lambda: "tools.nc: done" in log_text(app), what="the job to finish")
        await shown(pilot, app, (1600, 800, -800))  # Z-1 in the new offset: machine Z −2 mm
