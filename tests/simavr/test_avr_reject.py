"""Bad input on the real board firmware: each impossible segment and each
damaged frame is refused with an error that names what is wrong, and no
step pin moves."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from avr_sim import Outputs, run_input
from quadstep.protocol import (
    Ack,
    AckReason,
    Alarm,
    AlarmCode,
    Decoder,
    ErrorCode,
    ErrorReport,
    FieldId,
    Identify,
    Status,
    StatusReport,
    Stop,
    encode,
)
from quadstep.protocol.framing import cobs_encode, crc16, encode_frame


def segment_body(seq: int, n: int, mask: int, *axes: tuple[int, int, int]) -> bytes:
    body = bytes([0x10, seq]) + struct.pack("<HB", n, mask)
    for v0, vn, r in axes:
        body += struct.pack("<HHh", v0, vn, r)
    return body


def raw_segment(seq: int, n: int, mask: int, *axes: tuple[int, int, int]) -> bytes:
    """A SEGMENT frame built by hand, so it can break the rules the host's models enforce."""
    return encode_frame(segment_body(seq, n, mask, *axes))


GOOD = (4096, 4096, 0)
BAD_SEGMENTS = [
    ("n = 0", raw_segment(0, 0, 0b001, GOOD), FieldId.N, None),
    ("n = 1023", raw_segment(0, 1023, 0b001, GOOD), FieldId.N, None),
    ("axis 3 on a 3-axis board", raw_segment(0, 10, 0b1000, GOOD), FieldId.AXES, None),
    ("direction of an idle axis", raw_segment(0, 10, 0b0010_0001, GOOD), FieldId.DIRECTION, None),
    ("v0 = 4097", raw_segment(0, 10, 0b011, GOOD, (4097, 0, 0)), FieldId.V0, 1),
    ("vn = 4097", raw_segment(0, 10, 0b001, (0, 4097, 0)), FieldId.VN, 0),
    ("r = 4097", raw_segment(0, 10, 0b001, (100, 100, 4097)), FieldId.RESIDUAL, 0),
    ("r = 4096 at full speed", raw_segment(0, 10, 0b001, (4096, 4096, 4096)), FieldId.RESIDUAL, 0),
]


def replies(path: Path) -> list:
    frames = Decoder("to_host", axis_count=3).feed(path.read_bytes())
    assert all(not isinstance(f, Exception) for f in frames), frames
    return [f.message for f in frames]


@pytest.mark.parametrize("name,frame,field,axis", BAD_SEGMENTS, ids=[b[0] for b in BAD_SEGMENTS])
def test_impossible_segment_is_refused_and_nothing_moves(
    name: str, frame: bytes, field: FieldId, axis: int | None, avr_build: None, tmp_path: Path
) -> None:
    data = b"\x00" + encode(Identify(), 1) + frame + encode(Status(), 2)
    outputs = Outputs.in_dir(tmp_path)
    stats = run_input(data, outputs, tmp_path / "replies.bin")
    got = replies(tmp_path / "replies.bin")

    errors = [m for m in got if isinstance(m, ErrorReport)]
    assert len(errors) == 1, got
    assert errors[0].code == ErrorCode.BAD_FIELD and errors[0].field == field and errors[0].axis == axis
    assert errors[0].frame_type == 0x10 and errors[0].frame_seq == 0
    assert any(isinstance(m, Ack) and m.reason == AckReason.REJECTED for m in got)
    assert any(isinstance(m, Alarm) and m.code == AlarmCode.REJECTED_SEGMENT for m in got)
    status = [m for m in got if isinstance(m, StatusReport)][-1]
    assert status.position == (0, 0, 0) and status.motion_ticks == 0 and status.queue_fill == 0
    assert stats["motion"]["steps"] == [0, 0, 0] and stats["motion"]["dir_changes"] == 0
    assert outputs.load_edges() == []


def test_damaged_frames_are_reported_and_a_good_one_still_runs(avr_build: None, tmp_path: Path) -> None:
    good = encode(Stop(), 3)  # an intact frame: the line is in sync again; next_seq becomes 3
    body = segment_body(3, 100, 0b001, (4096, 0, 0))
    segment = encode_frame(body)
    flipped = body[:4] + bytes([body[4] ^ 0x01]) + body[5:]  # one bit off, the CRC of the original
    bad_crc = cobs_encode(flipped + struct.pack("<H", crc16(body))) + b"\x00"
    too_short = encode_frame(b"\x10")
    data = b"\x00" + bad_crc + too_short + b"\x07" * 70 + b"\x00" + good + segment + encode(Status(), 4)
    outputs = Outputs.in_dir(tmp_path)
    run_input(data, outputs, tmp_path / "replies.bin")
    got = replies(tmp_path / "replies.bin")

    codes = [m.code for m in got if isinstance(m, ErrorReport)]
    assert codes == [ErrorCode.BAD_CRC, ErrorCode.FRAME_TOO_SHORT, ErrorCode.FRAME_TOO_LONG]
    status = [m for m in got if isinstance(m, StatusReport)][-1]
    assert status.bad_crc == 1 and status.bad_frame == 2
    # The intact segment after the garbage runs: 100 ticks from full speed to rest.
    assert outputs.load_stats()["motion"]["steps"] == [50, 0, 0]
