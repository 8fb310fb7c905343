"""The screens at 80 × 24, pixel for pixel (a fresh emulator, known jogs and a known job), and that at that size
nothing wraps or is cut: every panel line, the key line with "? help", and the whole help text."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

from rich.text import Text

from quadstep.config import MachineConfig
from quadstep.job import load_job
from quadstep.toolpath import toolpath
from quadstep.tui.help import HelpScreen, help_text
from quadstep.tui.keys import JOB_KEY_LINE, KEY_LINE
from quadstep.tui.panels import JogPanel, MachinePanel, PositionPanel
from quadstep.tui.toolpath_view import ToolpathView
from test_tui import connected, make_app, shown

SIZE = (80, 24)


def job_file(tmp_path: Path) -> Path:
    job = tmp_path / "part.gcode"
    job.write_text("G21 G90\nG0 X5 Y5\nG1 X30 Y5 F3000\nG2 X30 Y25 I0 J10\nG1 X5 Y25\nG1 X5 Y5\nG0 X0 Y0\n")
    return job


def test_machine_screen_with_a_path(snap_compare, machine: MachineConfig, emulator_binary: Path,  # noqa: ANN001
                                    tmp_path: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    job = load_job(job_file(tmp_path), machine)

    async def run_before(pilot) -> None:  # noqa: ANN001
        await connected(pilot, app)
        app.machine.query_one(ToolpathView).show_path(toolpath(job.program, (0.0, 0.0, 0.0)))
        await pilot.press("right", "pagedown", "2", "plus")  # X+ 1 mm, Z− 1 mm, then step 0.1 mm, speed 50 %
        await shown(pilot, app, (80, 0, -400))
        # the link's counters say how busy this host was (a late answer is a retransmission), not
        # how the screen is laid out: counted afresh from here, they show a clean link
        stats = app.session.machine.stats
        for counter in fields(stats):
            setattr(stats, counter.name, 0)
        await pilot.pause(0.3)  # a few more identical status polls: nothing left to redraw

    assert snap_compare(app, terminal_size=SIZE, run_before=run_before)


def test_help_screen(snap_compare, machine: MachineConfig, emulator_binary: Path) -> None:  # noqa: ANN001
    app = make_app(machine, emulator_binary, free=True)

    async def run_before(pilot) -> None:  # noqa: ANN001
        await connected(pilot, app)
        await pilot.press("question_mark")
        await pilot.pause(0.2)

    assert snap_compare(app, terminal_size=SIZE, run_before=run_before)


async def test_nothing_wraps_or_is_cut_at_80_by_24(machine: MachineConfig, emulator_binary: Path,
                                                   tmp_path: Path) -> None:
    app = make_app(machine, emulator_binary, free=True, job_path=str(job_file(tmp_path)))
    async with app.run_test(size=SIZE) as pilot:
        await connected(pilot, app)
        await pilot.press("right")
        await shown(pilot, app, (80, 0, 0))
        screen = app.machine
        for panel, lines in ((PositionPanel, 1 + len(machine.axes)), (MachinePanel, 4), (JogPanel, 1)):
            widget = screen.query_one(panel)
            assert widget.content_size.height == lines, f"{panel.__name__} wraps"
            widest = max(len(line) for line in str(widget.render()).splitlines())
            assert widest <= widget.content_size.width, f"{panel.__name__} is cut"
        for widget in screen.query("*"):
            region = widget.region
            if widget.display and region.area:
                assert region.right <= SIZE[0] and region.bottom <= SIZE[1], f"{widget} leaves the screen"
        screen.log_line("a message longer than the log is wide, as a soft limit's or a refused job's can be, "
                        "wraps onto the next lines")
        await pilot.pause(0.1)
        log = screen.query_one("#log")
        assert max(strip.cell_length for strip in log.lines) <= log.scrollable_content_region.width
        keys = screen.query_one("#keys")
        for line in (KEY_LINE, JOB_KEY_LINE):
            plain = Text.from_markup(line).plain
            assert plain.endswith("? help") and len(plain) <= keys.content_size.width
        await pilot.press("o")  # the job dialog
        dialog = app.screen.query_one("#job-dialog")
        assert dialog.region.right <= SIZE[0] and dialog.region.bottom <= SIZE[1]
        await pilot.press("escape")
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        box = app.screen.query_one("#help")
        assert box.region.right <= SIZE[0] and box.region.bottom <= SIZE[1]
        text = Text.from_markup(help_text(app.session.settings))
        assert max(len(line) for line in text.plain.splitlines()) <= box.content_size.width
        assert box.max_scroll_y > 0  # taller than the screen: it scrolls (focused, so the arrows do it)
        await pilot.press("end")
        assert box.scroll_y == box.max_scroll_y
