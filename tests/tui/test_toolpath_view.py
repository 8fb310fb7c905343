"""The toolpath view while the tool moves (many times a second in a job): the travel box and the path are
drawn once for their configuration, path, size and extent, and only the tool and the origin again; what it
shows is what drawing everything afresh shows."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.config import MachineConfig
from quadstep.job import load_job
from quadstep.toolpath import toolpath
from quadstep.tui.canvas import Canvas
from quadstep.tui.toolpath_view import ToolpathView
from test_snapshot import job_file
from test_tui import connected, make_app


async def test_the_path_is_drawn_once_while_only_the_tool_moves(
    machine: MachineConfig, emulator_binary: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lines: list[int] = []
    draw_line = Canvas.line

    def counted(canvas: Canvas, *args, **options) -> None:  # noqa: ANN002, ANN003
        lines.append(1)
        draw_line(canvas, *args, **options)

    monkeypatch.setattr(Canvas, "line", counted)
    app = make_app(machine, emulator_binary, free=True)
    job = load_job(job_file(tmp_path), machine)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        view = app.machine.query_one(ToolpathView)
        view.show_path(toolpath(job.program, (0.0, 0.0, 0.0)))
        # no await from here on: no status update moves the tool meanwhile
        view.show(machine, (0.0, 0.0, 0.0), None)
        lines.clear()  # what the screen drew before the path was shown
        before = str(view.render())
        drawn = len(lines)
        assert drawn > 4  # the travel box and the path
        view.show(machine, (20.0, 15.0, 0.0), (5.0, 5.0, 0.0))  # inside the job's box: the same extent
        moved = str(view.render())
        assert len(lines) == drawn and moved != before  # the tool and the origin, not the path again
        view._drawn = None  # drawn afresh: the same picture
        assert str(view.render()) == moved and len(lines) == 2 * drawn
        view.toggle_extent()  # the whole travel: another extent, drawn again
        view.render()
        assert len(lines) == 3 * drawn
