"""Continuous jogs in a terminal that reports no key release: a single tap moves a short bounded
distance (what the jog speed covers in tap_time, at most tap_max) and stops by itself; its key's
repeats make the jog continuous, ended when they stop. The jog line says which the terminal allows."""

from __future__ import annotations

from pathlib import Path

from rich.text import Text

from quadstep.config import MachineConfig
from quadstep.jog import JogMode
from quadstep.tui.panels import JogPanel
from test_tui import connected, make_app, positions
from tui_helpers import FAST_RELEASE, hold_key, log_text, send_key, until


def jog_line(app) -> str:  # noqa: ANN001
    rendered = app.machine.query_one(JogPanel).render()
    return rendered.plain if isinstance(rendered, Text) else str(rendered)


async def test_a_single_tap_moves_a_short_bounded_distance(
    machine: MachineConfig, emulator_binary: Path
) -> None:
    app = make_app(machine, emulator_binary, free=False, settings=FAST_RELEASE)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("c", "plus", "plus")  # continuous at 100 % (50 mm/s on X)
        jogger = app.session.jogger
        assert jogger is not None and jogger.mode == JogMode.CONTINUOUS and jogger.taps
        assert jogger.speed(0) == 50.0
        await until(pilot, lambda: "CONTINUOUS (taps: no key-up)" in jog_line(app), what="mode")
        send_key(app, "right")  # one press, no repeat, no release
        await until(pilot, lambda: jogger.last_result is not None and not jogger.busy, what="tap")
        x = positions(app)[0]
        # at most tap_max = 1 mm (80 steps), never the 0.6 s first-repeat window at 50 mm/s (30 mm)
        assert 0 < x <= FAST_RELEASE.tap_max * 80
        assert x == round(min(FAST_RELEASE.tap_max, 50.0 * FAST_RELEASE.tap_time) * 80)
        # held: a tap, then the repeats keep it going until they stop
        await pilot.press("minus", "minus")  # 25 %: held 0.8 s, it stays short of the soft limit
        await hold_key(app, "right", 0.8)
        # (a loaded machine may deliver a repeat late: a tap again, then the repeats go on)
        await until(pilot, lambda: "release: decelerated to rest (HOLD)" in log_text(app),
                    what="the held jog to end on its repeats stopping")
        await until(pilot, lambda: not jogger.busy, what="rest")
        assert positions(app)[0] > x + 80


async def test_the_jog_line_says_the_terminal_reports_releases(
    machine: MachineConfig, emulator_binary: Path
) -> None:
    app = make_app(machine, emulator_binary, free=True, settings=FAST_RELEASE)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("c")
        await until(pilot, lambda: "(taps: no key-up)" in jog_line(app), what="taps")
        from quadstep.tui.kitty import KeyboardFlags

        app.post_message(KeyboardFlags(1 + 2 + 8 + 16))
        await until(pilot, lambda: "CONTINUOUS (to key-up)" in jog_line(app), what="key-up")
        jogger = app.session.jogger
        assert jogger is not None and not jogger.taps
