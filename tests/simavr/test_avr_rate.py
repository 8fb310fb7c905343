"""What the Uno's default tick rate is chosen for, run on the real binary in
simavr: three axes stepping every tick while the board takes 1,000
segments a second from the line, flow-controlled as a host sends them,
with no tick lost and every step where the host's model puts it. Cycles in
simavr are exact, so this holds or fails the same way on every machine."""

from __future__ import annotations


import numpy as np
import pytest

import avr_scenarios
from avr_sim import F_CPU, Outputs, avr_define, run_feed
from quadstep.kernel.engine_model import predict
from quadstep.protocol import encode
from quadstep.kernel.fixed import D

SEGMENTS_PER_SECOND = 1_000
SECONDS = 0.25


@pytest.fixture(scope="module")
def run(avr_build: None, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Outputs, object, int]:
    tick_hz = avr_define("QS_TICK_HZ")
    n = tick_hz // SEGMENTS_PER_SECOND  # ticks per segment at exactly 1,000 segments/s
    b = avr_scenarios.ChainBuilder(3)
    dirs = {0: 1, 1: -1, 2: 1}
    count = int(SECONDS * SEGMENTS_PER_SECOND)
    # A dwell first, so that the host fills the queue as it would at the start of a job.
    segments = [avr_scenarios.dwell()]
    segments += [b.segment(n, {a: (dirs[a], D, D) for a in range(3)}) for _ in range(count - 1)]
    segments.append(b.segment(n, {a: (dirs[a], D, 0) for a in range(3)}))
    frames = b"".join(encode(s, i & 0xFF) for i, s in enumerate(segments))
    outputs = Outputs.in_dir(tmp_path_factory.mktemp("rate"))
    motion = (count * n + 1022) / tick_hz
    stats = run_feed(frames, outputs, max_cycles=int((motion + 0.1) * F_CPU))
    return stats, outputs, predict(segments, axis_count=3), n


def test_every_segment_is_taken_in_time(run: tuple) -> None:
    """Had the board taken fewer than 1,000 segments/s, the queue would have
    run dry with the axes at full speed: a stop the board makes itself (STARVED), reported by HOLD_DONE."""
    stats, _, _, n = run
    feed = stats["feed"]
    assert n * SEGMENTS_PER_SECOND == avr_define("QS_TICK_HZ")
    assert feed["accepted"] == feed["frames"] == int(SECONDS * SEGMENTS_PER_SECOND) + 1, feed
    assert (feed["alarms"], feed["holds"], feed["errors"], feed["gap"], feed["queue_full"]) == (0, 0, 0, 0, 0), feed
    assert feed["bad_replies"] == 0, feed
    assert stats["wire"]["lost"] == 0


def test_three_axes_step_every_tick_exactly_as_predicted(run: tuple) -> None:
    stats, outputs, expected, n = run
    trace = outputs.load_trace()
    assert np.array_equal(trace, expected.steps)
    ticks, per_tick = np.unique(trace[:, 0], return_counts=True)
    full = int(np.sum(per_tick == 3))
    assert full >= (int(SECONDS * SEGMENTS_PER_SECOND) - 1) * n  # all but the last, stopping, segment
    assert stats["tick_isr"]["steps3"]["count"] >= full - 1


def test_no_tick_is_lost_or_late(run: tuple) -> None:
    stats, _, _, _ = run
    period = stats["tick_cycles"]
    assert stats["motion"]["ticks_missed"] == 0
    assert stats["motion"]["tick_late_max"] <= period // 4
    # Room left for the rest of the firmware: the step interrupt, three axes
    # stepping, takes at most three quarters of a tick on average.
    assert stats["tick_isr"]["steps3"]["mean"] <= 0.75 * period
