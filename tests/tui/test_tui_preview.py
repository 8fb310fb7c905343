"""A job is shown before it moves: o completes the path typed, Enter plans it whole and shows its
size, box, planned time and warnings; Esc drops it with nothing moved, Enter runs it."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from quadstep.tui.job_dialog import JobDialog
from quadstep.tui.preview import PathSuggester
from test_tui import connected, make_app, positions, shown
from tui_helpers import log_text, until


async def test_the_path_suggester_completes_files_and_folders(tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    (tmp_path / "part-a.gcode").write_text("G0 X1\n")
    suggest = PathSuggester()
    assert await suggest.get_suggestion(f"{tmp_path}/part-") == f"{tmp_path}/part-a.gcode"
    assert await suggest.get_suggestion(f"{tmp_path}/parts") is None  # a folder typed whole
    assert await suggest.get_suggestion(f"{tmp_path}/part") == f"{tmp_path}/part-a.gcode"
    assert await suggest.get_suggestion(f"{tmp_path}/q") is None
    assert await suggest.get_suggestion(f"{tmp_path}/nowhere/x") is None


async def test_a_job_is_shown_then_dropped_or_run(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path
) -> None:
    job = tmp_path / "square-with-m0.gcode"
    job.write_text("G21 G90\nG1 X10 Y0 F1200\nM0\nG1 X10 Y5\n")
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("o")
        assert isinstance(app.screen, JobDialog)
        await pilot.press(*f"{tmp_path}/square-w")
        await pilot.press("right", "enter")  # → takes the completion
        await until(pilot, lambda: app.machine.preview is not None, what="the job shown")
        text = log_text(app)
        assert f"job {job}: 4 lines, 2 moves" in text
        assert "  box (G54): X 10.00…10.00  Y 0.00…5.00  Z 0.00…0.00" in text  # its targets, as check's
        assert "  warning: it stops for the operator at line(s) 3 (g goes on)" in text
        view = app.machine.query_one("#toolpath")
        assert view.border_subtitle == "0×5 mm · 1 s · Enter runs"
        await pilot.press("escape")
        await until(pilot, lambda: "job dropped: nothing moved" in log_text(app), what="dropped")
        assert app.machine.preview is None and positions(app) == (0, 0, 0)
        await pilot.press("enter")  # nothing shown: Enter does nothing
        assert app.machine.job is None
        await pilot.press("o", "enter")  # the path is kept: shown again
        await until(pilot, lambda: app.machine.preview is not None, what="shown again")
        await pilot.press("enter")
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.paused_at == 3,
                    what="the pause")
        await pilot.press("g")
        await until(pilot, lambda: "square-with-m0.gcode: done" in log_text(app), what="the end")
        await shown(pilot, app, (800, 400, 0))
