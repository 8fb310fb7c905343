"""The emulator with a simulated machine (--machine): the firmware's inputs against the mechanics. Switch and probe
edges latch with no error at all, a hard limit leaves no step after its tick, a motion armed by PROBE ends at its
edge or says it missed, and each input's polarity, debounce and action hold end to end."""

from __future__ import annotations

import math
import random
import time
from pathlib import Path

import pytest

from machine_helpers import STEPS_PER_MM, along, events, read_trace_with_carriage, write_machine
from quadstep.link import AlarmError, FirmwareError, Link, Stopped, input_status, until_input, wait_rest
from quadstep.kernel.motion import AxisMove
from quadstep.protocol import (AlarmCode, Config, ErrorCode, HoldDone, Input, InputCause, InputChange, Probe, ProbeMissed,
                               Segment)

DECEL = (2000, 2000, 2000, 0)
NO_DEBOUNCE = (0,) * 12


def emulator(start_emulator, tmp_path: Path, machine: str, **options: object):
    path = write_machine(tmp_path / "machine.toml", machine)
    return start_emulator(free=True, tick_hz=32000, axes=3, queue=16, trace=tmp_path / "trace.csv",
                          extra_args=["--machine", str(path), *options.pop("extra", [])], **options)


def seek(link: Link, axis: int, mm: float, which: Input, level: int = 1, feed: float = 10.0):
    """A move along `axis` armed to end where `which` reaches `level`."""
    start = tuple(link.status().position[:3])
    return until_input(link, Probe(input=which, level=level, decel=DECEL), along(axis, start, mm, feed), timeout=60)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_switch_latches_the_exact_step_of_the_carriage_crossing_it(start_emulator, tmp_path: Path,
                                                                      seed: int) -> None:
    rng = random.Random(seed)
    start = rng.randint(4000, 12000)
    backlash = rng.choice([0.0, 2.5, 7.25, 12.0])
    at = rng.uniform(-50, 50)
    emu = emulator(start_emulator, tmp_path, f"""
[[axis]]
start = {start}
backlash = {backlash}
[axis.limit_min]
at = {at}
hysteresis = 5
""")
    with Link.open(emu.url) as link:
        hit = seek(link, 0, -60, Input.LIMIT_0, feed=rng.choice([5.0, 20.0, 40.0]))
        assert isinstance(hit, InputChange) and hit.cause == InputCause.TRIGGER and hit.became_active(Input.LIMIT_0)
        rest = link.status()
    summary = emu.stop()
    # The carriage follows half the dead band behind the motor: the first motor step that puts it at or
    # below the switch's point closes it.
    crossing = math.floor(at - backlash / 2)
    assert hit.position[0] == crossing - start
    (edge,) = events(summary, "limit_0")
    assert edge["tick"] == hit.motion_ticks
    assert edge["carriage"][0] <= at < edge["carriage"][0] + 1
    # The hold after it came to rest beyond, and the firmware counted every step.
    assert rest.position[0] < hit.position[0]
    assert summary["machine"]["axes"][0]["steps"] == rest.position[0]


def test_a_hard_limit_during_a_job_stops_every_axis_at_its_tick(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
start = 0
[axis.limit_max]
at = 3000.5
[[axis]]
start = 0
""")
    with Link.open(emu.url) as link:
        with pytest.raises(AlarmError) as raised:
            for segment in along(0, (0, 0, 0), 20, 30) + along(1, (8000, 0, 0), 5):
                link.send(segment, timeout=30)
            link.wait_idle(timeout=30)
        alarm = raised.value.alarm
        assert alarm.code == AlarmCode.HARD_LIMIT
        change = next(e for e in link.input_changes if e.cause == InputCause.HARD_LIMIT)
        link.stop()
    summary = emu.stop()
    trace = read_trace_with_carriage(tmp_path / "trace.csv")
    (edge,) = events(summary, "limit_max_0")
    assert alarm.position[0] == 3001 == change.position[0] == summary["machine"]["axes"][0]["steps"]
    assert alarm.motion_ticks == change.motion_ticks == edge["tick"]
    assert trace[:, 0].max() == edge["tick"]  # not one step after the edge's tick, on any axis
    assert summary["alarm"] == "NONE" and summary["machine"]["axes"][1]["pulses"] == 0


def test_a_probe_that_never_touches_says_so_where_it_rests(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
[[axis]]
[[axis]]
[probe]
[[probe.target]]
kind = "plate"
z = -4000
""")
    with Link.open(emu.url) as link:
        missed = seek(link, 2, -5, Input.PROBE)
        assert isinstance(missed, ProbeMissed)
        assert missed.position == link.status().position == (0, 0, -2000)
        touched = seek(link, 2, -10, Input.PROBE, feed=2)
        assert isinstance(touched, InputChange) and touched.position[2] == -4000
        # Away from the plate until it lets go (G38.4/G38.5): the probe has no hysteresis here.
        released = seek(link, 2, 0.25, Input.PROBE, level=0, feed=1)
        assert isinstance(released, InputChange) and released.position[2] == -3999
    assert len(events(emu.stop(), "probe")) == 2


class PausingLink:
    """A real Link, on a host that is busy elsewhere for `pause` seconds right after it sends `after` (a
    garbage collection, another program's turn)."""

    def __init__(self, link: Link, after: Segment, pause: float) -> None:
        self.link, self.after, self.pause = link, after, pause

    def send(self, message, *args, **kwargs) -> None:  # noqa: ANN001
        self.link.send(message, *args, **kwargs)
        if message is self.after:
            time.sleep(self.pause)

    def __getattr__(self, name: str):  # noqa: ANN204
        return getattr(self.link, name)


def test_a_take_up_before_the_seek_runs_unarmed_so_a_pause_after_it_spends_no_probe(start_emulator,
                                                                                      tmp_path: Path) -> None:
    """A seek whose stream begins with a backlash take-up (here: a rest tick and a short move of the motor
    alone, rest to rest, as takeup_stream makes them) on a host that pauses right after the take-up: the
    board comes to rest there with its queue empty, which a PROBE armed before the take-up would have
    taken for its motion's end (PROBE_MISSED), and the seek would then have run unarmed into the switch
    (here a hard limit too). The PROBE is armed after the take-up, at rest, and the seek ends at the edge."""
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
start = 8000
[axis.limit_min]
at = 0.0
hysteresis = 5
""")
    with Link.open(emu.url) as link:
        rest_tick = Segment(n=1, axes=tuple(AxisMove(axis=a, direction=1, v0=0, vn=0, r=0) for a in range(3)))
        take_up = along(0, (0, 0, 0), 0.05, 5.0)
        seek_move = along(0, (STEPS_PER_MM // 20, 0, 0), -60, 10.0)
        slow = PausingLink(link, take_up[-1], 0.5)  # the take-up lasts 10 ms
        hit = until_input(slow, Probe(input=Input.LIMIT_0, level=1, decel=DECEL),  # type: ignore[arg-type]
                          [rest_tick, *take_up, *seek_move], timeout=60)
        assert isinstance(hit, InputChange) and hit.cause == InputCause.TRIGGER, hit
        assert link.report_count(ProbeMissed) == 0
        assert hit.position[0] == 0 - 8000  # the first motor step that puts the carriage at the switch
    emu.stop()


def test_a_switch_closed_already_refuses_the_seek_and_pulls_off_first(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
start = -20
[axis.limit_min]
at = 0
hysteresis = 6.5
""")
    with Link.open(emu.url) as link:
        assert input_status(link).is_active(Input.LIMIT_0)
        with pytest.raises(FirmwareError) as refused:
            seek(link, 0, -5, Input.LIMIT_0)
        assert refused.value.report.code == ErrorCode.INPUT_AT_LEVEL
        link.stop()
        off = seek(link, 0, 5, Input.LIMIT_0, level=0, feed=2)
        assert isinstance(off, InputChange) and not off.became_active(Input.LIMIT_0)
        assert off.position[0] == 27  # opens at its point plus the hysteresis: carriage -20 + 27 = 7 >= 6.5
        assert not input_status(link).is_active(Input.LIMIT_0)


def test_polarity_and_debounce_of_a_bouncing_normally_closed_switch(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
seed = 5
[[axis]]
start = 8000
[axis.limit_min]
at = 0
normally_closed = true
bounce = 3
bounce_ticks = 60
""")
    debounce = list(NO_DEBOUNCE)
    debounce[Input.LIMIT_0] = 80
    with Link.open(emu.url) as link:
        # Active low by default: the closed contact of a switch at rest reads active.
        assert input_status(link).is_active(Input.LIMIT_0)
        link.send(Config(invert=1 << Input.LIMIT_0, enabled=0x0FFF, hard_limits=1, debounce=tuple(debounce),
                         hold_decel=DECEL))
        link.drain(timeout=5)
        assert not input_status(link).is_active(Input.LIMIT_0)
        hit = seek(link, 0, -30, Input.LIMIT_0, feed=5)
        assert isinstance(hit, InputChange) and hit.cause == InputCause.TRIGGER
    summary = emu.stop()
    edges = events(summary, "limit_0")
    assert [e["cause"] for e in edges] == ["switch"] + ["bounce"] * 6
    assert hit.position[0] == -8000 and hit.motion_ticks == edges[0]["tick"]  # the first contact, exactly


def test_abort_feed_hold_and_cycle_start_buttons(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
[[press]]
input = "cycle_start"
at_tick = 2000
ticks = 50
[[press]]
input = "feed_hold"
at_tick = 6000
ticks = 50
[[press]]
input = "abort"
at_tick = 30000
ticks = 320000
""")
    with Link.open(emu.url) as link:
        with pytest.raises(Stopped):  # the feed hold drops what is queued and in flight
            stream = link.generation  # whenever the hold comes, no segment after it joins the next stream
            for segment in along(0, (0, 0, 0), 10, 20):
                link.send(segment, timeout=10, generation=stream)
            link.wait_idle(timeout=30, generation=stream)
        held = wait_rest(link, timeout=30)
        done = link.last_report(HoldDone)
        changes = link.input_changes
        with pytest.raises(AlarmError) as raised:
            for segment in along(0, tuple(held.position[:3]), 10, 20):
                link.send(segment, timeout=10)
            link.wait_idle(timeout=30)
        assert raised.value.alarm.code == AlarmCode.E_STOP
        assert link.stop().alarm == AlarmCode.E_STOP  # the button is still down (for 10 s)
    assert [c.cause for c in changes] == [InputCause.CYCLE_START, InputCause.REPORT, InputCause.FEED_HOLD,
                                          InputCause.REPORT]
    assert changes[2].motion_ticks == 6000 and changes[0].motion_ticks == 2000
    # The feed hold is the main loop's HOLD, taken at the tick boundary after the one it was latched at (on
    # a board, as soon as the main loop gets to it); it begins after its window of 12 decisions.
    assert done is not None and done.hold_tick == 6001 + 12 and done.position == held.position
    assert held.state.name == "IDLE" and 0 < held.position[0] < 4000


def test_steps_against_a_hard_stop_are_lost_and_backlash_shows_in_the_trace(start_emulator, tmp_path: Path) -> None:
    emu = emulator(start_emulator, tmp_path, """
[[axis]]
start = 0
backlash = 4
hard_max = 100
""")
    with Link.open(emu.url) as link:
        for segment in along(0, (0, 0, 0), 0.5, 5) + along(0, (200, 0, 0), -0.1, 5):
            link.send(segment, timeout=10)
        status = link.wait_idle(timeout=10)
    summary = emu.stop()
    axis = summary["machine"]["axes"][0]
    assert status.position[0] == axis["steps"] == 160
    assert axis["lost_steps"] == 200 - 102  # the motor may still take up the band beyond the stop
    assert axis["motor"] == 102 - 40 and axis["carriage"] == 62 + 2
    trace = read_trace_with_carriage(tmp_path / "trace.csv")
    back = trace[trace[:, 2] == -1]
    # Reversing, the motor crosses the whole dead band before the carriage moves.
    assert (back[:4, 4] == 100).all() and back[4, 4] == 99
