"""HOLD end to end: the real firmware core in the emulator, on a pseudo-terminal, through the Link,
against engine_model.predict_hold, checked step by step in the emulator's trace."""

from __future__ import annotations

import random
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from hold_helpers import assert_deceleration_within, check_hold, planned_job, read_events
from host_helpers import read_trace
from host_helpers import RawPort

from quadstep.kernel.engine_model import predict_hold, predict_underrun
from quadstep.link import AlarmError, FirmwareError, Link, Stopped, hold, hold_async
from quadstep.protocol import POSITION_MAX, AlarmCode, Capability, ErrorCode, ErrorReport, Event, FieldId, Hold, Segment, SetPosition, State, Status, StatusReport, encode
from quadstep.kernel.fixed import D, DECEL_MAX, N_MAX
from quadstep.kernel.motion import AxisMove


def test_the_deceleration_check_catches_a_hold_twice_as_hard() -> None:
    """hold_helpers.assert_deceleration_within on predicted steps: it passes the deceleration asked for
    and fails twice that."""
    mv = AxisMove(axis=0, direction=1, v0=D, vn=D, r=0)
    for decel in (300, 2000, DECEL_MAX // 2):
        asked = predict_hold([Segment(n=N_MAX, axes=(mv,))], 10, [decel] * 4)
        hard = predict_hold([Segment(n=N_MAX, axes=(mv,))], 10, [2 * decel] * 4)
        assert_deceleration_within(asked.steps, 0, 10, asked.motion_ticks, decel)
        with pytest.raises(AssertionError, match="decelerated faster"):
            assert_deceleration_within(hard.steps, 0, 10, hard.motion_ticks, decel)


def stream_in_background(link: Link, segments: list[Segment]) -> threading.Thread:
    def run() -> None:
        try:
            for seg in segments:
                link.send(seg)
        except (Stopped, FirmwareError):
            pass  # the hold dropped what was left, or it was refused while holding

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


@pytest.mark.parametrize("seed", range(5))
def test_a_hold_at_a_random_moment_stops_exactly_as_predicted(start_emulator, tmp_path: Path, seed: int) -> None:
    """Real time: the job streams while the HOLD arrives whenever it does."""
    rng = random.Random(seed)
    segments = planned_job(rng, 50_000)
    decels = [rng.choice([rng.randint(800, DECEL_MAX), DECEL_MAX, 800]) for _ in range(4)]
    emu = start_emulator(trace=tmp_path / "trace.csv", extra_args=["--events", str(tmp_path / "events.csv")])
    with Link.open(emu.url) as link:
        assert link.identify().capabilities & Capability.HOLD
        sender = stream_in_background(link, segments)
        time.sleep(rng.uniform(0.1, 0.6))
        sent_ns = time.monotonic_ns()
        done = hold(link, decels, timeout=30)
        sender.join(10)
        status = link.status()
    summary = emu.stop()
    assert status.state == State.IDLE and status.queue_fill == 0
    assert list(status.position) == list(done.position)
    assert 0 < done.hold_tick < sum(s.n for s in segments)
    check_hold(tmp_path / "trace.csv", segments, done, decels)
    pred = predict_hold(segments, done.hold_tick, decels)
    assert summary["segments_done"] == pred.held  # the held segment and the tail never completed
    assert summary["motion_ticks"] == done.motion_ticks
    events = read_events(tmp_path / "events.csv")
    assert [e["event"] for e in events] == ["hold"]
    assert int(events[0]["tick"]) == done.hold_tick
    assert int(events[0]["monotonic_ns"]) > sent_ns  # the same clock: it acted after it was sent


def reports_of(port: RawPort, kind: type, count: int) -> list:
    """The next `count` reports of one kind, skipping others (ACKs, SPACE acks)."""
    found: list = []
    while len(found) < count:
        found += [item.message for item in port.collect(1) if isinstance(getattr(item, "message", None), kind)]
    return found


def segment_starts(segments: list[Segment]) -> list[int]:
    return [int(t) for t in np.cumsum([0] + [s.n for s in segments])]


@pytest.mark.parametrize("where", ["first tick", "boundary", "last tick of a segment", "middle"])
def test_a_hold_injected_at_a_chosen_tick_of_a_free_running_job(start_emulator, tmp_path: Path, where: str) -> None:
    """Free-running, with the HOLD injected by the emulator's --hold-at at an exact motion tick. The
    whole job goes out in one write that the queue holds, so every segment is queued before it runs."""
    rng = random.Random(where)
    segments = planned_job(rng, 30_000)
    starts = segment_starts(segments)
    tick = {"first tick": 0, "boundary": starts[6], "last tick of a segment": starts[7] - 1,
            "middle": starts[9] + segments[9].n // 2}[where]
    decel = rng.randint(1000, DECEL_MAX)
    job = b"".join(encode(seg, seq) for seq, seg in enumerate(segments))
    assert len(segments) <= 127 and len(job) < 2048  # one queue, one write the line delivers whole
    emu = start_emulator(free=True, queue=127, trace=tmp_path / "trace.csv",
                         extra_args=["--hold-at", f"{tick}:{decel}"])
    with RawPort(emu.url) as port:
        port.write(b"\x00" + job)
        done = reports_of(port, Event, 1)[0]
        port.write(encode(Status(), 200))
        status = reports_of(port, StatusReport, 1)[-1]
    emu.stop()
    # The hold begins after its window (the firmware's QS_TRIGGER_TICKS = 12 decisions, a few more where a
    # segment begins inside it), exactly where HOLD_DONE says.
    assert tick + 12 <= done.hold_tick <= tick + 24
    assert status.state == State.IDLE and status.queue_fill == 0
    assert list(status.position) == list(done.position)
    assert status.rejected == 0  # every segment was queued before the hold
    check_hold(tmp_path / "trace.csv", segments, done, [decel] * 4)


def test_hold_while_idle_reports_where_it_rests_and_repeats_itself(free_link: Link) -> None:
    free_link.send(SetPosition(positions={0: 5, 1: -6, 2: 7, 3: -8}))
    free_link.drain(5)
    done = hold(free_link, [100])
    assert (done.hold_tick, done.motion_ticks, done.position) == (0, 0, (5, -6, 7, -8))
    seg = Segment(n=300, axes=(AxisMove(axis=0, direction=1, v0=D, vn=0, r=0),))
    free_link.send(seg)
    free_link.wait_idle(10)
    done = hold(free_link, [100, 200, 300, 400])
    assert (done.hold_tick, done.motion_ticks, done.position[0]) == (300, 300, 5 + 150)
    # Nothing moved since: asking again gives the same report (how a lost HOLD_DONE is recovered).
    assert hold(free_link, [100]) == done
    free_link.send(SetPosition(positions={0: 0}))  # the link carries on after holds
    free_link.drain(5)


def test_a_lost_hold_done_is_asked_for_again(start_emulator) -> None:
    """The emulator drops the firmware's 4th frame: after IDENTIFY_REPLY, STATUS_REPORT and the HOLD's
    answer, the HOLD_DONE. The link sees the firmware at rest without it and asks again."""
    emu = start_emulator(free=True, extra_args=["--drop-tx-frame", "4"])
    with Link.open(emu.url) as link:
        link.poll_interval = 0.2
        sent = link.stats.frames_sent
        done = hold(link, [50])
        assert (done.hold_tick, done.motion_ticks, done.position) == (0, 0, (0, 0, 0, 0))
        assert link.stats.frames_sent >= sent + 3  # HOLD, STATUS, HOLD again
    assert emu.stop()["tx_frames_dropped"] == 1


def test_bad_decelerations_are_refused_before_anything_is_sent(free_link: Link) -> None:
    sent = free_link.stats.frames_sent
    with pytest.raises(ValueError, match=r"axis 2 is 0; limit 1\.\.8191"):
        hold(free_link, [10, 10, 0, 10])
    with pytest.raises(ValueError, match=r"axis 0 is 8192"):
        hold(free_link, [8192])
    with pytest.raises(ValueError, match=r"1 or 4 decelerations"):
        hold(free_link, [10, 10])
    assert free_link.stats.frames_sent == sent


def test_the_firmware_refuses_a_bad_hold_and_the_job_goes_on(start_emulator) -> None:
    emu = start_emulator(axes=3)
    seg = Segment(n=N_MAX, axes=(AxisMove(axis=1, direction=1, v0=D // 2, vn=D // 2, r=0),))
    with RawPort(emu.url) as port:
        port.write(b"\x00" + b"".join(encode(seg, seq) for seq in range(30)))
        # Built raw: the Hold model itself refuses values the wire could still carry.
        port.write(encode(Hold.model_construct(decel=(10, 0, 10, 0)), 50))
        port.write(encode(Hold.model_construct(decel=(10, 10, 10, 10)), 51))
        errors = reports_of(port, ErrorReport, 2)
        port.write(encode(Status(), 52))
        status = reports_of(port, StatusReport, 1)[0]
    assert [(e.code, e.field, e.axis, e.frame_type, e.frame_seq) for e in errors] == [
        (ErrorCode.BAD_FIELD, FieldId.DECEL, 1, 0x04, 50),
        (ErrorCode.BAD_FIELD, FieldId.DECEL, 3, 0x04, 51),
    ]
    assert status.state == State.RUNNING and status.next_seq == 30 and status.queue_fill >= 1


def test_hold_in_alarm_raises_the_alarm(free_link: Link) -> None:
    free_link.send(SetPosition(positions={0: POSITION_MAX}))
    free_link.send(Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=D, vn=0, r=0),)))  # past POSITION_MAX
    with pytest.raises((AlarmError, FirmwareError)):
        free_link.wait_idle(10)
    with pytest.raises(AlarmError) as caught:
        hold(free_link, [100])
    assert caught.value.alarm.code == AlarmCode.REJECTED_SEGMENT
    assert caught.value.alarm.position[0] == POSITION_MAX
    assert free_link.stop().state == State.IDLE


def test_hold_at_a_starved_board_takes_it_up_with_the_stop_repeated(free_link: Link) -> None:
    segment = Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=D, vn=D, r=0),))
    free_link.send(segment)
    with pytest.raises(Stopped):
        free_link.wait_idle(10)  # the underrun, once its controlled stop is at rest: STARVED
    stop = predict_underrun([segment], [256] * 4, axis_count=4)  # the firmware's stop deceleration before CONFIG
    done = hold(free_link, [100])
    assert (done.hold_tick, done.motion_ticks) == (100, stop.motion_ticks) and stop.motion_ticks > 100
    assert list(done.position) == stop.positions
    assert free_link.status().state == State.IDLE


def test_stop_during_a_long_hold_stops_at_once(start_emulator, tmp_path: Path) -> None:
    emu = start_emulator(trace=tmp_path / "trace.csv")
    cruise = AxisMove(axis=3, direction=-1, v0=D, vn=D, r=0)
    with Link.open(emu.url) as link:
        for _ in range(20):
            link.send(Segment(n=N_MAX, axes=(cruise,)))
        deadline = time.monotonic() + 5
        while link.status().state != State.RUNNING:  # under way: the hold comes to a moving axis
            assert time.monotonic() < deadline
        future = hold_async(link, [1])  # a step per tick, losing one quantum per tick: minutes to stop
        deadline = time.monotonic() + 5
        while link.status().state != State.HOLDING:
            assert time.monotonic() < deadline
        time.sleep(0.2)
        stopped = link.stop()
        with pytest.raises(Stopped):
            future.result(5)
    emu.stop()
    trace = read_trace(tmp_path / "trace.csv")
    assert stopped.state == State.IDLE and stopped.queue_fill == 0
    assert stopped.position[3] == -len(trace)
    assert stopped.motion_ticks >= trace[:, 0].max()
    # Still a step a tick when STOP came (the hold from there takes minutes): it ended the hold at once.
    # (Not a count of ticks since the HOLD: a paced board on a busy computer runs behind the wall clock.)
    assert int(np.count_nonzero(trace[:, 0] > stopped.motion_ticks - 100)) >= 99
