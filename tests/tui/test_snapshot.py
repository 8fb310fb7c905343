"""The machine screen, pixel for pixel: a fixed size, a fresh emulator, two known jogs."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from test_tui import connected, make_app, shown


def test_machine_screen(snap_compare, machine: MachineConfig, emulator_binary: Path) -> None:  # noqa: ANN001
    app = make_app(machine, emulator_binary, free=True)

    async def run_before(pilot) -> None:  # noqa: ANN001
        await connected(pilot, app)
        await pilot.press("right", "pagedown", "2", "plus")  # X+ 1 mm, Z− 1 mm, then step 0.1 mm, speed 50 %
        await shown(pilot, app, (80, 0, -400))
        await pilot.pause(0.3)  # a few more identical status polls: nothing left to redraw

    assert snap_compare(app, terminal_size=(100, 30), run_before=run_before)
