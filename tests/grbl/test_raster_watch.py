"""What the front door's raster watch makes of the lines queued: a raster run once three moves
along X at one feed carry two powers or more under the laser, a run still growing while the last
line may go on with it, and nothing on a machine that burns no rasters."""

from __future__ import annotations

from pathlib import Path

from quadstep.config import load_config
from quadstep.grbl.raster_watch import RasterWatch
from quadstep.planner.program import Dwell, Item, LinearMove, OutputState, SetOutputs

REPO = Path(__file__).resolve().parents[2]
LASER = load_config(REPO / "examples" / "laser-uno.toml")
ROUTER = load_config(REPO / "examples" / "router-uno.toml")


def pixels(powers: list[float], x: float = 10.0, step: float = 0.1, feed: float = 100.0) -> list[Item]:
    items: list[Item] = []
    for k, power in enumerate(powers, start=1):
        items.append(SetOutputs(line=k, state=OutputState(spindle=4, speed=power)))
        items.append(LinearMove(line=k, target=(x + k * step, 10.0, 0.0), feed=feed))
    return items


def start() -> list[Item]:
    return [SetOutputs(line=0, state=OutputState(spindle=4)), LinearMove(line=0, target=(10.0, 10.0, 0.0), feed=None)]


def test_three_pixels_of_two_powers_make_a_run_that_may_grow() -> None:
    watch = RasterWatch(LASER, takes_rasters=True)
    watch.add(start())
    assert not watch.growing and not watch.holds_run
    watch.add(pixels([100, 500]))
    assert watch.growing and not watch.holds_run  # two moves: a cut so far
    watch.add(pixels([900], x=10.2))
    assert watch.growing and watch.holds_run
    watch.add([LinearMove(line=9, target=(0.0, 0.0, 0.0), feed=None)])  # the rapid home ends it
    assert not watch.growing and watch.holds_run
    watch.clear()  # the lines were taken
    assert not watch.growing and not watch.holds_run


def test_one_power_a_turn_or_a_dwell_is_no_run() -> None:
    watch = RasterWatch(LASER, takes_rasters=True)
    watch.add(start() + pixels([500, 500]))
    assert watch.growing and not watch.holds_run  # two moves: maybe a row's start
    watch.add(pixels([500, 500], x=10.2))  # a cut at one power, which an open job takes
    assert not watch.growing and not watch.holds_run
    watch.add([Dwell(line=5, seconds=0.1)])
    assert not watch.growing
    watch.add(pixels([100, 200], x=10.4) + pixels([300, 400], x=10.6, step=-0.1))  # two, then back
    assert watch.growing and not watch.holds_run
    watch.add([LinearMove(line=9, target=(10.6, 10.0, 0.0), feed=50.0)])  # another feed: a new run
    assert watch.growing and not watch.holds_run


def test_a_machine_that_burns_no_rasters_watches_nothing() -> None:
    for config, takes in ((LASER, False), (ROUTER, True)):
        watch = RasterWatch(config, takes_rasters=takes)
        watch.add(start() + pixels([100, 500, 900, 300]))
        assert not watch.growing and not watch.holds_run
