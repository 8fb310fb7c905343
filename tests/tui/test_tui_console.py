"""The console (MDI) line, the jog queue and the message log, through Textual's pilot on the real emulator."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from quadstep.tui.console import ConsoleLine
from test_tui import connected, make_app, positions, shown
from tui_helpers import log_text, send_key, until
from tui_layout import plain_lines
from quadstep.tui.panels import JogPanel


def plain(widget) -> str:  # noqa: ANN001
    return "\n".join(plain_lines(widget))


async def type_line(pilot, text: str) -> None:  # noqa: ANN001
    await pilot.press(*[{" ": "space"}.get(c, c) for c in text])


async def test_a_typed_line_runs_checked_whole_with_history(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        assert "jog keys off" not in plain(app.machine.query_one(JogPanel))
        await pilot.press("colon")
        console = app.machine.query_one(ConsoleLine)
        assert console.has_focus
        # the key line and the jog line say who has the keys
        assert plain(app.machine.query_one("#keys")).startswith(" MDI has the keys ")
        assert plain(app.machine.query_one(JogPanel)).startswith("jog keys off: the console (MDI)")
        await type_line(pilot, "G1 X5 F600")
        await pilot.press("enter")
        await until(pilot, lambda: "MDI: done" in log_text(app), what="the line to run")
        await shown(pilot, app, (400, 0, 0))
        await type_line(pilot, "Y2.5")  # G1 and F carry over from the line before
        await pilot.press("enter")
        await until(pilot, lambda: log_text(app).count("MDI: done") == 2, what="the second line")
        await shown(pilot, app, (400, 200, 0))
        await type_line(pilot, "G1 X50")  # outside the travel: refused whole, nothing moves
        await pilot.press("enter")
        await until(pilot, lambda: "MDI not started" in log_text(app), what="the refusal")
        assert "MDI not started: X 50.000 mm is outside the travel 0.000 … 40.000 mm" in log_text(app)
        assert positions(app) == (400, 200, 0)
        await pilot.press("up")
        assert console.value == "G1 X50"
        await pilot.press("up", "up")
        assert console.value == "G1 X5 F600"
        await pilot.press("down")
        assert console.value == "Y2.5"
        await pilot.press("escape")  # the keys go back to jogging
        assert not console.has_focus and console.value == ""
        assert plain(app.machine.query_one("#keys")).startswith("←→↑↓ PgUp/Dn jog")
        assert plain(app.machine.query_one(JogPanel)).startswith("jog INCREMENTAL")
        await pilot.press("right")
        await shown(pilot, app, (480, 200, 0))


async def test_a_line_without_motion_sets_the_work_offset(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("right")
        await shown(pilot, app, (80, 0, 0))
        await pilot.press("colon")
        await type_line(pilot, "G10 L20 P1 X0")
        await pilot.press("enter")
        await until(pilot, lambda: "MDI: done (no motion; G54 active)" in log_text(app), what="the offset")
        await until(pilot, lambda: app.machine.snapshot is not None and app.machine.snapshot.work_mm[0] == 0.0,
                    what="work X 0")


async def test_repeated_messages_are_counted_not_repeated(machine: MachineConfig, emulator_binary: Path) -> None:
    app = make_app(machine, emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        for _ in range(20):  # X at travel_min: every press says so
            send_key(app, "left")
        await until(pilot, lambda: app.session.jogger is not None and not app.session.jogger.busy
                    and not app.session.jogger.queue.queued_mm(), what="the presses")
        await pilot.pause(0.3)
        assert log_text(app).count("X-: stops at the soft limit travel_min = 0.000 mm") == 1
        await pilot.press("right")
        await shown(pilot, app, (80, 0, 0))
        await pilot.press("c")  # another message: the count of the repeated one comes first
        await until(pilot, lambda: "jog mode: continuous" in log_text(app), what="the mode")
        lines = [str(line.text) for line in app.machine.query_one("#log").lines]
        counted = [line for line in lines if "the line above" in line]
        assert len(counted) == 1 and "more times" in counted[0]


async def test_a_refused_jog_clears_its_to_go(machine: MachineConfig, emulator_binary: Path) -> None:
    unhomed = machine.model_copy(update={"homing_required": True})  # every jog refused: not homed
    app = make_app(unhomed, emulator_binary, free=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("4")
        for _ in range(3):
            send_key(app, "right")
        await until(pilot, lambda: "home the machine first (quadstep home, or h in the TUI)"
                    in log_text(app), what="the refusal")
        jogger = app.session.jogger
        assert jogger is not None
        await until(pilot, lambda: not jogger.queue.queued_mm(), what="the queue to clear")
        await until(pilot, lambda: "to go" not in plain(app.machine.query_one(JogPanel)),
                    what="the jog line")
        assert positions(app) == (0, 0, 0)
