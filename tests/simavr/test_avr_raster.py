"""RASTER on the real Mega build and the Uno's laser build in simavr (the Uno's own build has no room
for it: capability bit 14 clear): the lines are taken, the steps are the host's prediction, and the
laser's PWM begins each pixel's power within a tick of the step that crosses its boundary."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from avr_raster_pixels import AXES, PixelRun, pixel_starts, run_hold_in_line, run_pixels
from quadstep.kernel.engine_model import predict


@pytest.fixture(scope="module", params=sorted(AXES))
def run(avr_build: None, tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest) -> PixelRun:
    return run_pixels(request.param, Path(tmp_path_factory.mktemp("raster")))


def test_the_board_takes_raster_lines_and_steps_as_predicted(run: PixelRun) -> None:
    feed = run.stats["feed"]
    assert feed["accepted"] == feed["frames"] == 7 and feed["alarms"] == feed["errors"] == 0, feed
    assert run.stats["motion"]["ticks_missed"] == 0, run.stats["motion"]
    expected = predict(run.segments, [0] * run.axis_count, axis_count=run.axis_count)
    assert np.array_equal(run.trace, expected.steps)


def test_each_pixel_begins_within_a_tick_of_the_step_that_crosses_its_boundary(run: PixelRun) -> None:
    """The tick that decides the crossing step restarts the PWM's period with the pixel's power (the step
    goes out at the next tick), so the period that shows the power, high for (power + 1) / 256 of it,
    begins within a tick of that step's edge, before it: at every boundary of both lines; a line's first
    pixel within two ticks of its first step (at half a step a tick, its first decision is up to a tick
    before)."""
    tick = run.stats["tick_cycles"]
    starts = pixel_starts(run)
    boundaries = [s for i, s in enumerate(starts) if i % 5]
    assert len(starts) == 10 and all(-tick <= s <= 0 for s in boundaries), starts
    assert all(-2 * tick <= s <= 0 for s in starts[::5]), starts


@pytest.mark.parametrize("board", sorted(AXES))
def test_a_hold_inside_a_line_darkens_the_laser_as_it_begins(board: str, avr_build: None, tmp_path: Path) -> None:
    """A HOLD in the middle of a line of long pixels: the pixels shine through the hold's window, and from
    the hold's first decelerating tick the pin stays low (the setting around the line is dark) while the
    axis slows to rest."""
    held = run_hold_in_line(board, tmp_path)
    assert held.stats["motion"]["ticks_missed"] == 0, held.stats["motion"]
    rises = [cycle for cycle, level in held.pwm if level]
    assert rises and rises[0] < held.hold_cycle, (rises[:3], held.hold_cycle)  # the line was lit
    after = [(cycle, level) for cycle, level in held.pwm if cycle > held.hold_cycle]
    assert len(after) <= 1 and all(level == 0 for _, level in after), after  # at most the fall, at once
    assert all(cycle - held.hold_cycle <= 2 * held.tick for cycle, _ in after), after
    assert held.pwm[-1][1] == 0, held.pwm[-3:]
