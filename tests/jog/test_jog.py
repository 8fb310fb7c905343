"""The jog module on the real emulator, without any UI: presets, soft limits, HOLD and re-anchoring."""

from __future__ import annotations

import math
import threading
import time

import pytest
from waiting import wait_until

from quadstep.config import MachineConfig
from quadstep.jog import JogMode, Jogger, JogResult, JogSettings
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.planner.lookahead import PLAN_ACCEL_FRACTION
from quadstep.protocol import State

from tui_helpers import FAST_RELEASE, HELD_UNTIL_STOPPED

X, Y, Z = 0, 1, 2


def jogger_on(link: Link, config: MachineConfig, settings: JogSettings | None = None, **options: object) -> Jogger:
    return Jogger(Machine(link, config), settings, **options)  # type: ignore[arg-type]


def place(jogger: Jogger, **steps: int) -> None:
    """Put axes at step positions with SET_POSITION (the machine has no homing)."""
    index = {"X": X, "Y": Y, "Z": Z}
    jogger.machine.set_position({index[name]: value for name, value in steps.items()})
    jogger.sync()


def hold_repeats(jogger: Jogger, axis: int, direction: int, seconds: float, first_delay: float = 0.3) -> None:
    """Press a continuous jog key and let the 'terminal' repeat it every 40 ms for `seconds`."""
    jogger.press(axis, direction)
    end = time.monotonic() + seconds
    time.sleep(min(first_delay, seconds))
    while time.monotonic() < end:
        jogger.press(axis, direction)
        time.sleep(0.04)


def test_incremental_presets_move_exactly_the_preset_distances(fast_link: Link, machine: MachineConfig) -> None:
    jogger = jogger_on(fast_link, machine)
    assert jogger.settings.step_presets == (0.01, 0.1, 1.0, 10.0)
    expected_mm = 0.0
    for index, presses in ((2, 2), (3, 1), (1, 3), (0, 5)):
        jogger.select_step(index)
        for _ in range(presses):
            result = jogger.step(X, 1)
            expected_mm += jogger.distance
            # each press lands on the step nearest the accumulated distance: no rounding drift
            assert result.position[X] == round(expected_mm * 80)
            assert fast_link.status().position[X] == round(expected_mm * 80)
    assert expected_mm == pytest.approx(12.35)
    assert fast_link.status().position[: 3] == (988, 0, 0)  # 12.35 mm × 80; five 0.01 mm presses made 4 steps
    jogger.select_step(2)
    jogger.step(Z, -1)
    jogger.step(Y, 1)
    assert fast_link.status().position[: 3] == (988, 80, -400)


def test_incremental_jog_stops_at_the_soft_limit_ahead(fast_link: Link, machine: MachineConfig) -> None:
    jogger = jogger_on(fast_link, machine)
    result = jogger.step(X, -1)  # at travel_min already
    assert result.end is None and result.position[X] == 0
    assert result.message == "X-: stops at the soft limit travel_min = 0.000 mm"
    place(jogger, X=2800)  # 35 mm
    jogger.select_step(3)  # 10 mm would pass travel_max = 40
    result = jogger.step(X, 1)
    assert result.message == "X+: stops at the soft limit travel_max = 40.000 mm"
    assert result.end is not None and result.end.ended_by == "done"
    assert fast_link.status().position[X] == 3200
    with pytest.raises(ValueError, match="step preset 5 does not exist"):
        jogger.select_step(4)


def test_outside_the_travel_only_the_way_back_is_open(fast_link: Link, machine: MachineConfig) -> None:
    jogger = jogger_on(fast_link, machine)
    place(jogger, X=4000, Z=400)  # 50 mm (travel 0 … 40) and +1 mm (travel −20 … 0)
    assert jogger.step(X, 1).end is None
    assert jogger.step(Z, 1).end is None
    jogger.step(X, -1)
    jogger.step(Z, -1)
    assert fast_link.status().position[: 3] == (3920, 0, 0)


@pytest.mark.parametrize(("index", "mm_per_s"), [(1, 5.0), (4, 50.0)])
def test_speed_presets_are_fractions_of_the_axis_max(
    fast_link: Link, machine: MachineConfig, index: int, mm_per_s: float
) -> None:
    jogger = jogger_on(fast_link, machine)
    jogger.select_step(3)
    jogger.speed_index = index
    assert jogger.speed(X) == mm_per_s
    before = fast_link.status().motion_ticks
    jogger.step(X, 1)
    ticks = fast_link.status().motion_ticks - before
    # 10 mm at v with 500 mm/s² ramps (as planned, a little under the limit): d/v + v/a seconds
    expected = (10.0 / mm_per_s + mm_per_s / (500 * PLAN_ACCEL_FRACTION)) * 50000
    assert ticks == pytest.approx(expected, rel=0.01)


def test_continuous_jog_left_alone_comes_to_rest_exactly_on_the_soft_limit(
    paced_link: Link, machine: MachineConfig
) -> None:
    jogger = jogger_on(paced_link, machine, HELD_UNTIL_STOPPED)
    place(jogger, X=2400)  # 30 mm; 10 mm to the limit at 50 mm/s
    jogger.mode = JogMode.CONTINUOUS
    jogger.speed_index = 4
    jogger.jog(X, 1)
    assert jogger.wait_idle(10)
    result = jogger.last_result
    assert result is not None and result.end is not None
    assert result.end.ended_by == "done"
    assert result.message == "X+: reached the soft limit travel_max = 40.000 mm"
    status = paced_link.status()
    assert status.state == State.IDLE and status.alarm is None
    assert status.position[X] == 3200 == jogger.position[X]


def test_continuous_jog_released_decelerates_with_hold_and_re_anchors(
    paced_link: Link, machine: MachineConfig
) -> None:
    results: list[JogResult] = []
    jogger = jogger_on(paced_link, machine, FAST_RELEASE, on_finish=results.append)
    jogger.mode = JogMode.CONTINUOUS
    hold_repeats(jogger, Y, 1, 0.5)
    assert jogger.wait_idle(5)
    assert len(results) == 1
    result = results[0]
    assert result.end is not None
    assert result.end.ended_by == "release"
    assert result.end.held and result.end.hold_tick is not None
    status = paced_link.status()
    assert status.state == State.IDLE and status.queue_fill == 0
    # between start and the soft limit, and where the board says it rests
    assert 0 < status.position[Y] < 3200
    assert jogger.position == result.position == status.position[:3]
    # the next jog starts from the rest position: exactly one step preset further
    jogger.mode = JogMode.INCREMENTAL
    jogger.select_step(2)
    jogger.step(Y, 1)
    assert paced_link.status().position[Y] == status.position[Y] + 80


def test_stop_key_ends_a_continuous_jog_with_hold(paced_link: Link, machine: MachineConfig) -> None:
    jogger = jogger_on(paced_link, machine, HELD_UNTIL_STOPPED)
    jogger.mode = JogMode.CONTINUOUS
    jogger.jog(X, 1)
    wait_until(lambda: paced_link.status().position[X] > 0, what="the jog under way")
    result = jogger.stop()
    assert result is not None and result.end is not None
    assert result.end.ended_by == "stop" and result.end.held
    assert result.end.stop_event_ns is not None
    status = paced_link.status()
    assert status.state == State.IDLE
    assert 0 < status.position[X] < 3200 and status.position[X] == result.position[X]


def test_continuous_jog_keeps_little_motion_queued(paced_link: Link, machine: MachineConfig) -> None:
    """A host that vanishes mid-jog leaves at most the lookahead queued, not a full queue."""
    settings = JogSettings(first_repeat_timeout=5.0, repeat_timeout=5.0)
    jogger = jogger_on(paced_link, machine, settings)
    jogger.mode = JogMode.CONTINUOUS
    jogger.speed_index = 1  # 5 mm/s: 8 s to the limit, segments of 1022 ticks once cruising
    fills: list[int] = []
    jogger.jog(X, 1)
    stop_sampling = threading.Event()

    def sample() -> None:
        while not stop_sampling.is_set():
            fills.append(paced_link.status().queue_fill)
            time.sleep(0.02)

    sampler = threading.Thread(target=sample)
    sampler.start()
    time.sleep(0.6)
    stop_sampling.set()
    sampler.join()
    jogger.stop()
    assert len(fills) > 10
    # the lookahead in ticks covers at most `whole` segments of 1022 ticks, plus the one running
    whole = math.ceil(settings.lookahead * machine.tick_hz / 1022)
    assert whole + 1 < paced_link.identify().queue_capacity
    assert 2 <= max(fills) <= whole + 1


def test_a_held_key_queues_one_step_and_drops_the_repeats(fast_link: Link, machine: MachineConfig) -> None:
    """Twenty repeats of a 10 mm step arriving at once: one waits, the rest are dropped; 0.01 mm steps all count."""
    jogger = jogger_on(fast_link, machine)
    jogger.select_step(3)  # 10 mm at 25 % of 50 mm/s: about 0.85 s a step
    taken = [s for s in (jogger.queue_step(X, 1) for _ in range(20)) if s is not None]
    assert len(taken) == 1 and jogger.queue.dropped == 19
    assert jogger.queue.queued_mm() == {X: 10.0}
    for step in taken:
        jogger.run_queued(step)
    assert fast_link.status().position[X] == 800
    assert jogger.queue.queued_mm() == {}
    jogger.select_step(0)  # 0.01 mm: a tap's worth of motion each, every tap runs
    taps = [jogger.queue_step(X, -1) for _ in range(5)]
    assert all(t is not None for t in taps)
    for step in taps:
        assert step is not None
        jogger.run_queued(step)
    assert fast_link.status().position[X] == 796  # 9.95 mm
    dropped = jogger.queue_step(Z, -1)  # Z has its own step: 1 mm
    assert dropped is not None and dropped.distance == 1.0
    jogger.stop()  # the stop key drops what waits
    assert jogger.run_queued(dropped) is None
    assert fast_link.status().position[Z] == 0
