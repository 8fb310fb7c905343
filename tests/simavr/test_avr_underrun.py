"""An underrun on the real AVR firmware, in simavr: the queue runs dry behind segments that end with three axes
near full speed, and the board stops them itself (STARVED) exactly as the host's model of a hold at the last
segment's end says. (What the stop's tick costs is tests/bench/bench_avr.py's to print.)"""

from __future__ import annotations

from pathlib import Path

import pytest
from hold_helpers import check_hold

from quadstep.kernel.fixed import D
from quadstep.kernel.motion import AxisMove
from quadstep.protocol import Decoder, Event, Segment, State, encode

import avr_sim

F_CPU = avr_sim.F_CPU
STOP_DECEL = 256  # the firmware's stop deceleration until CONFIG sets it (QS_DEFAULT_STOP_DECEL)


@pytest.mark.parametrize("n", [300, 317])
def test_an_underrun_stops_exactly_as_predicted(avr_build: None, tmp_path: Path, n: int) -> None:
    segments = [Segment(n=n, axes=tuple(AxisMove(axis=a, direction=1, v0=D - 1, vn=D - 1, r=0) for a in range(3)))
                for _ in range(3)]
    job = b"\x00" + b"".join(encode(s, i) for i, s in enumerate(segments))
    outputs = avr_sim.Outputs.in_dir(tmp_path, "underrun")
    replies = tmp_path / "replies.bin"
    # From near full speed at 256 / 2^24 step per tick², the stop takes about 65,500 ticks (2 s)
    stats = avr_sim.run_input(job, outputs, replies, max_cycles=3 * F_CPU, until_idle=False)
    events = [item.message for item in Decoder("to_host", axis_count=3).feed(replies.read_bytes())
              if isinstance(getattr(item, "message", None), Event)]
    assert len(events) == 1  # HOLD_DONE: where the stop began (the last segment's end) and where it rests
    assert events[0].hold_tick == 3 * n
    check_hold(outputs.trace, segments, events[0], [STOP_DECEL] * 3, axis_count=3)
    assert stats["motion"]["state"] == State.STARVED
