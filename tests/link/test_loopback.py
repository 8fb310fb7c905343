"""The host link against the real firmware core, running in the emulator on a pseudo-terminal."""

from __future__ import annotations

import random
import struct
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest
from host_helpers import RawPort, assert_trace_is_prediction, random_segments, read_trace
from waiting import wait_until

from quadstep.emulator import Emulator
from quadstep.kernel.engine_model import predict, predict_underrun
from quadstep.link import FirmwareError, Link, Stopped, hold
from quadstep.protocol import Ack, AckReason, Alarm, AlarmCode, CubicSegment, ErrorCode, ErrorReport, FieldId, Frame, HoldDone, POSITION_MAX, Segment, SetPosition, State, Status, StatusReport, Stop, encode
from quadstep.kernel.fixed import D, N_MAX
from quadstep.kernel.motion import AxisMove, CubicAxis
from quadstep.protocol.framing import cobs_encode, encode_frame


def stream(link: Link, segments: list[Segment]) -> StatusReport:
    for seg in segments:
        link.send(seg)
    return link.wait_idle(timeout=60)


def test_identify_reports_the_emulator(free_link: Link) -> None:
    ident = free_link.identify()
    assert (ident.protocol_version, ident.board, ident.axis_count, ident.raster_ring) == (3, 0, 4, 1024)
    assert (ident.queue_capacity, ident.speed_shift, ident.n_max, ident.tick_hz) == (32, 12, 1022, 50000)
    assert ident.capabilities & 0b11 == 0b11
    status = free_link.status()
    assert status.state == State.IDLE and status.position == (0, 0, 0, 0)


def test_random_segments_execute_exactly_as_predicted(free_emulator: Emulator, free_link: Link) -> None:
    segments = random_segments(random.Random(1), 300)
    final = stream(free_link, segments)
    expected = predict(segments)
    assert list(final.position) == expected.positions
    assert final.motion_ticks == expected.motion_ticks == sum(s.n for s in segments)
    assert final.segments_done == free_link.segments_done == 300
    assert (final.bad_crc, final.bad_frame, final.rejected, final.seq_gap, final.seq_dup) == (0, 0, 0, 0, 0)
    assert free_link.stats.retransmits == 0
    assert_trace_is_prediction(free_emulator.trace, segments)  # type: ignore[arg-type]
    summary = free_emulator.stop()
    assert summary["motion_ticks"] == expected.motion_ticks
    assert summary["segments_done"] == 300
    assert [summary[f"position_{axis}"] for axis in range(4)] == expected.positions


def test_set_position_offsets_every_later_step(free_emulator: Emulator, free_link: Link) -> None:
    start = [1000, -2000, POSITION_MAX - 5000, -POSITION_MAX + 5000]
    free_link.send(SetPosition(positions=dict(enumerate(start))))
    segments = random_segments(random.Random(2), 20)
    final = stream(free_link, segments)
    assert list(final.position) == predict(segments, start).positions


def test_malformed_frames_are_counted_and_the_next_good_frame_works(free_emulator: Emulator) -> None:
    good_segment = Segment(n=10, axes=(AxisMove(axis=0, direction=1, v0=D, vn=0, r=0),))
    with RawPort(free_emulator.url) as raw:
        raw.write(b"\x00")
        raw.write(encode(Status(), 1))
        (first,) = raw.collect(1)
        next_seq = first.message.next_seq
        garbage = bytes(range(1, 40)) + b"\x00"  # bad COBS
        bad_crc = bytearray(encode(good_segment, next_seq))
        bad_crc[-3] ^= 0x01
        truncated = cobs_encode(encode(good_segment, next_seq)[1:3]) + b"\x00"  # 2 bytes: too short
        too_long = encode_frame(bytes([0x10, next_seq]) + bytes(range(1, 70)))
        unknown = encode_frame(bytes([0x3E, next_seq]))
        bad_length = encode_frame(bytes([0x10, next_seq, 5, 0]))
        raw.write(garbage + bytes(bad_crc) + truncated + too_long + unknown + bad_length)
        errors = raw.collect(6)
        codes = [e.message.code for e in errors if isinstance(e, Frame) and isinstance(e.message, ErrorReport)]
        assert codes == [
            ErrorCode.BAD_COBS, ErrorCode.BAD_CRC, ErrorCode.FRAME_TOO_SHORT, ErrorCode.FRAME_TOO_LONG,
            ErrorCode.UNKNOWN_TYPE, ErrorCode.BAD_LENGTH,
        ]
        assert [(e.message.frame_type, e.message.frame_seq) for e in errors[4:]] == [(0x3E, next_seq), (0x10, next_seq)]
        raw.write(encode(good_segment, next_seq))
        ack = raw.collect(1)[0].message
        assert isinstance(ack, Ack) and ack.reason == AckReason.ACCEPTED and ack.next_seq == (next_seq + 1) & 0xFF

        def status_now() -> StatusReport:
            raw.write(encode(Status(), 2))
            while True:  # past any SPACE ack
                for frame in raw.collect(1):
                    if isinstance(frame.message, StatusReport):
                        return frame.message

        wait_until(lambda: status_now().segments_done == 1, what="the segment run")
        status = status_now()
    assert (status.bad_frame, status.bad_crc, status.rejected) == (3, 1, 2)
    assert status.position[0] == 5 and status.segments_done == 1


def dropping_emulator(start_emulator, tmp_path: Path, option: str, k: int) -> Emulator:
    return start_emulator(free=True, trace=tmp_path / "trace.csv", extra_args=(option, str(k)))


@pytest.mark.parametrize(
    "option, k",
    [
        ("--drop-rx-frame", 5),  # third segment: the next frames earn GAPs
        ("--corrupt-rx-frame", 5),  # BAD_CRC, then GAPs
        ("--drop-rx-frame", 2 + 40),  # the last segment: only the retransmission timeout finds it
        ("--drop-rx-frame", 2 + 1),  # the first segment
    ],
)
def test_frame_lost_on_the_wire_is_resent_and_executed_once(start_emulator, tmp_path: Path, option: str, k: int) -> None:
    emu = dropping_emulator(start_emulator, tmp_path, option, k)
    segments = random_segments(random.Random(k), 40)
    with Link.open(emu.url) as link:  # frames 1 and 2 are IDENTIFY and STATUS
        final = stream(link, segments)
        assert link.stats.retransmits >= 1
        if k < 42:
            assert link.stats.gaps >= 1 and final.seq_gap >= 1
    assert list(final.position) == predict(segments).positions
    assert final.segments_done == 40
    assert_trace_is_prediction(emu.trace, segments)  # type: ignore[arg-type]


def test_lost_ack_costs_a_duplicate_not_a_second_execution(start_emulator, tmp_path: Path) -> None:
    # Paced at 2 kHz the segment runs 0.5 s, longer than the retransmission timeout,
    # so no SPACE ack can stand in for the lost ACK (firmware frames: 1 IDENTIFY_REPLY,
    # 2 STATUS_REPORT, 3 the ACK of the segment).
    emu = start_emulator(tick_hz=2000, trace=tmp_path / "trace.csv", extra_args=("--drop-tx-frame", "3"))
    segment = Segment(n=1000, axes=(AxisMove(axis=2, direction=-1, v0=1000, vn=0, r=0),))
    with Link.open(emu.url, rto=0.2) as link:
        final = stream(link, [segment])
        # The keep-alive STATUS (0.1 s without a write while the segment runs) usually repairs the lost
        # ACK before the timeout resends the frame; a resend is answered DUPLICATE.
        assert link.stats.duplicates == link.stats.retransmits <= 1
    assert final.seq_dup == link.stats.retransmits and final.segments_done == 1
    assert list(final.position) == predict([segment]).positions
    assert_trace_is_prediction(emu.trace, [segment])  # type: ignore[arg-type]


def test_invalid_segment_is_refused_with_its_field_and_raises_an_alarm(free_emulator: Emulator) -> None:
    with RawPort(free_emulator.url) as raw:
        raw.write(b"\x00" + encode(Status(), 1))
        seq = raw.collect(1)[0].message.next_seq
        body = bytes([0x10, seq]) + struct.pack("<HB", 100, 0b0110) + struct.pack("<HHhHHh", 10, 20, 0, 4097, 0, 0)
        raw.write(encode_frame(body))
        error, ack, alarm = (f.message for f in raw.collect(3))
        assert error == ErrorReport(code=ErrorCode.BAD_FIELD, frame_type=0x10, frame_seq=seq, field=FieldId.V0, axis=2)
        assert isinstance(ack, Ack) and ack.reason == AckReason.REJECTED and ack.next_seq == (seq + 1) & 0xFF
        assert isinstance(alarm, Alarm) and alarm.code == AlarmCode.REJECTED_SEGMENT
        assert alarm.position == (0, 0, 0, 0)
        raw.write(encode(Status(), 2))
        status = raw.collect(1)[0].message
        assert status.state == State.ALARM and status.alarm == AlarmCode.REJECTED_SEGMENT and status.rejected == 1
        good = Segment(n=5, axes=(AxisMove(axis=0, direction=1, v0=0, vn=0, r=0),))
        raw.write(encode(good, (seq + 1) & 0xFF))
        error, ack = (f.message for f in raw.collect(2))
        assert error.code == ErrorCode.ALARM_ACTIVE and ack.reason == AckReason.REJECTED
        raw.write(encode(Stop(), 77))
        stopped = raw.collect(1)[0].message
        assert stopped.state == State.IDLE and stopped.alarm is None and stopped.next_seq == 77


def test_the_boot_id_is_random_unless_given(start_emulator, emulator_binary: Path) -> None:
    emu = start_emulator(extra_args=("--boot-id", "4660"))
    with Link.open(emu.url) as link:
        assert link.identify().boot_id == 4660
    emu.stop()
    refused = subprocess.run([str(emulator_binary), "--boot-id", "65536"], capture_output=True, text=True, timeout=10)
    assert refused.returncode == 2
    assert "--boot-id must be a whole number from 0 to 65535, got '65536'" in refused.stderr


def test_underrun_holds_then_starves_with_exact_positions_and_hold_takes_it_up(start_emulator, tmp_path: Path) -> None:
    """The queue runs dry at speed: a controlled stop from where the segment ended, at the firmware's stop
    deceleration (256 before any CONFIG), every step as predicted, then STARVED (no alarm) at the rest
    positions: the link restarts the stream, segments are refused BUSY, and a HOLD takes the board up again."""
    emu = start_emulator(trace=tmp_path / "trace.csv")
    ends_moving = Segment(
        n=800, axes=(AxisMove(axis=0, direction=1, v0=2000, vn=3000, r=0), AxisMove(axis=3, direction=-1, v0=100, vn=90, r=-7))
    )
    expected = predict_underrun([ends_moving], [256] * 4)
    alarms: list = []
    with Link.open(emu.url) as link:
        link.on_report(lambda report: alarms.append(report) if isinstance(report, Alarm) else None)
        link.send(ends_moving)
        with pytest.raises(Stopped):
            link.wait_idle(timeout=10)
        assert link.stats.starvations == 1
        status = link.status()
        assert status.state == State.STARVED and status.alarm is None
        assert list(status.position) == expected.positions and status.motion_ticks == expected.motion_ticks > 800
        starved = link.last_report(HoldDone)
        assert starved is not None and starved.hold_tick == 800 and list(starved.position) == expected.positions
        link.send(ends_moving)  # planned for motion the stop discarded: refused, nothing runs
        with pytest.raises(FirmwareError) as caught:
            link.drain(timeout=10)
        assert caught.value.report.code == ErrorCode.BUSY
        assert link.status().state == State.STARVED and link.stats.starvations == 1
        done = hold(link, [100])
        assert (done.hold_tick, done.motion_ticks) == (800, expected.motion_ticks)  # the stop's, repeated
        assert list(done.position) == expected.positions
        assert link.status().state == State.IDLE and alarms == []
        at_rest = Segment(n=50, axes=(AxisMove(axis=1, direction=1, v0=4096, vn=0, r=0),))
        final = stream(link, [at_rest])
    after = predict([at_rest], expected.positions, start_tick=expected.motion_ticks)
    assert list(final.position) == after.positions
    emu.stop()
    steps = np.concatenate([predict([ends_moving]).steps, expected.steps, after.steps])
    assert np.array_equal(read_trace(emu.trace), steps)  # type: ignore[arg-type]


@pytest.mark.parametrize("n", [1, 100])
def test_an_underrun_too_slow_to_step_again_stops_at_the_segments_end(start_emulator, tmp_path: Path, n: int) -> None:
    """A cubic segment ends at 20 / 2^31 step a tick with nothing behind it: the stop from its end finds
    nothing that would move one tick on, so it takes no tick and the board starves where the segment
    ended. The emulator's trace clock keeps to the core's motion ticks through it, and what runs after the
    HOLD lands as predicted."""
    emu = start_emulator(free=True, axes=3, trace=tmp_path / "trace.csv")
    crawl = CubicSegment(n=n, axes=(CubicAxis(axis=1, speed=20),))
    after = Segment(n=50, axes=(AxisMove(axis=0, direction=1, v0=4096, vn=0, r=0),))
    with Link.open(emu.url) as link:
        link.send(crawl)
        with pytest.raises(Stopped):
            link.wait_idle(timeout=10)
        status = link.status()
        assert status.state == State.STARVED and status.motion_ticks == n and list(status.position) == [0, 0, 0]
        done = hold(link, [100])
        assert (done.hold_tick, done.motion_ticks) == (n, n)
        final = stream(link, [after])
    expected = predict([after], [0, 0, 0], start_tick=n, axis_count=3)
    assert list(final.position) == expected.positions
    summary = emu.stop()
    assert summary["motion_ticks"] == n + after.n
    assert np.array_equal(read_trace(emu.trace), expected.steps)  # type: ignore[arg-type]


def test_set_position_while_moving_is_refused_busy(start_emulator) -> None:
    emu = start_emulator(tick_hz=5000)
    with Link.open(emu.url) as link:
        link.send(Segment(n=1000, axes=(AxisMove(axis=0, direction=1, v0=0, vn=0, r=0),)))
        link.send(SetPosition(positions={0: 5}))
        with pytest.raises(FirmwareError) as caught:
            link.drain(timeout=5)
        assert caught.value.code == "BUSY" and caught.value.report.frame_type == 0x11
        status = link.stop()
        assert status.state == State.IDLE and status.position == (0, 0, 0, 0)
        link.send(SetPosition(positions={0: 5}))
        assert link.wait_idle(timeout=5).position == (5, 0, 0, 0)


def test_stop_during_motion_keeps_positions_exact(start_emulator, tmp_path: Path) -> None:
    """A sender blocked on the window gets Stopped; positions stay exact; the session goes on."""
    emu = start_emulator(tick_hz=10000, queue=4, trace=tmp_path / "trace.csv")
    segment = Segment(n=1000, axes=(AxisMove(axis=1, direction=-1, v0=2048, vn=2048, r=0),))
    outcome: list[BaseException] = []

    def sender(link: Link) -> None:
        try:
            for _ in range(20):
                link.send(segment)
        except BaseException as exc:  # noqa: BLE001 - the test inspects it
            outcome.append(exc)

    with Link.open(emu.url) as link:
        thread = threading.Thread(target=sender, args=(link,))
        thread.start()
        wait_until(lambda: link.segments_done >= 1, what="the first segment run")  # the sender waits on the window
        status = link.stop()
        thread.join(5)
        assert len(outcome) == 1 and isinstance(outcome[0], Stopped)
        assert status.state == State.IDLE and status.queue_fill == 0
        moved = status.position[1]
        assert -1000 * 20 // 2 < moved < 0
        final = stream(link, [Segment(n=10, axes=(AxisMove(axis=1, direction=1, v0=4096, vn=0, r=0),))])
        assert final.position[1] == moved + 5
    emu.stop()
    trace = read_trace(emu.trace)  # type: ignore[arg-type]
    assert int(trace[:, 2].sum()) == moved + 5


def test_frames_sent_ahead_of_the_queue_are_written_as_the_board_frees_slots(
    start_emulator, tmp_path: Path
) -> None:
    """send(ahead=10) returns with the board's 3 slots full and 10 more frames waiting in the window;
    the link's threads write each once a report frees a slot: never a frame the board has no room
    for, and every step where the segments put it."""
    emu = start_emulator(queue=3, tick_hz=2000, trace=tmp_path / "trace.csv")
    # the board's 3 slots full for 1.5 s while the other ten are sent: they wait in the window
    slow = Segment(n=N_MAX, axes=(AxisMove(axis=0, direction=1, v0=1024, vn=1024, r=0),))
    everything = [slow] * 3 + random_segments(random.Random(7), 10, axis_count=2)
    with Link.open(emu.url) as link:
        for segment in everything:
            link.send(segment, ahead=10)
        assert link.in_flight >= 10 and link.segments_done == 0
        final = link.wait_idle(timeout=30)
        assert link.stats.queue_full == 0 and link.stats.retransmits == 0
    assert list(final.position[:2]) == predict(everything, axis_count=2).positions[:2]
    emu.stop()
    assert_trace_is_prediction(emu.trace, everything, axis_count=2)  # type: ignore[arg-type]


def test_small_queue_flow_control_never_overflows(start_emulator, tmp_path: Path) -> None:
    emu = start_emulator(queue=3, free=True, trace=tmp_path / "trace.csv")
    segments = random_segments(random.Random(5), 30)
    with Link.open(emu.url) as link:
        assert link.identity.queue_capacity == 3  # type: ignore[union-attr]
        final = stream(link, segments)
        assert link.stats.queue_full == 0 and link.stats.retransmits == 0
    assert list(final.position) == predict(segments).positions
    assert_trace_is_prediction(emu.trace, segments)  # type: ignore[arg-type]


def test_segments_streamed_while_another_thread_asks_for_status_arrive_once_and_in_order(
        start_emulator, tmp_path: Path) -> None:
    """The writer is woken for what a report makes due (frames waiting for free slots), not for
    every report: a stream into a 3-slot queue, with STATUS requests from another thread all along,
    runs every frame once and in order."""
    emu = start_emulator(queue=3, free=True, trace=tmp_path / "trace.csv")
    segments = random_segments(random.Random(6), 400)
    statuses: list[StatusReport] = []
    with Link.open(emu.url) as link:
        done = threading.Event()

        def ask() -> None:
            while not done.is_set():
                statuses.append(link.status())

        asker = threading.Thread(target=ask)
        asker.start()
        try:
            final = stream(link, segments)
        finally:
            done.set()
            asker.join(timeout=10)
        assert link.stats.retransmits == 0 and link.stats.queue_full == 0
    assert len(statuses) > 10  # requests went out while the segments did
    assert (final.bad_crc, final.bad_frame, final.rejected, final.seq_gap, final.seq_dup) == (0, 0, 0, 0, 0)
    assert list(final.position) == predict(segments).positions
    assert_trace_is_prediction(emu.trace, segments)  # type: ignore[arg-type]


def test_segments_done_unwraps_past_65535_and_space_acks_report_progress(free_emulator: Emulator,
                                                                          free_link: Link) -> None:
    count = 65_536 + 300
    spaces: list[Ack] = []
    free_link.on_report(lambda report: spaces.append(report) if isinstance(report, Ack) else None)
    tick = Segment(n=1)
    for _ in range(count):
        free_link.send(tick)
    final = free_link.wait_idle(timeout=120)
    assert final.segments_done == free_link.segments_done == count
    assert final.motion_ticks == count
    assert spaces and all(a.reason == AckReason.SPACE for a in spaces)
    assert spaces[-1].done == count & 0xFFFF
