"""CRC, COBS and the frame splitter, beyond the fixed vectors."""

from __future__ import annotations

import struct

from hypothesis import given
from hypothesis import strategies as st

from quadstep.protocol import DecodeError, Decoder, ErrorCode, Frame, Identify, Segment, encode
from quadstep.kernel.motion import AxisMove
from quadstep.protocol.framing import (
    FrameSplitter,
    FramingError,
    check_block,
    cobs_decode,
    cobs_encode,
    crc16,
    encode_frame,
)


def test_crc_check_value() -> None:
    assert crc16(b"123456789") == 0x29B1


@given(st.binary(max_size=1000))
def test_cobs_round_trip_has_no_zero(block: bytes) -> None:
    encoded = cobs_encode(block)
    assert 0 not in encoded
    assert len(encoded) <= len(block) + 1 + len(block) // 254
    if len(block) <= 62:
        assert cobs_decode(encoded) == block


def test_cobs_run_boundaries() -> None:
    assert cobs_encode(b"") == b"\x01"
    assert cobs_encode(b"\x00") == b"\x01\x01"
    assert cobs_encode(bytes(range(1, 255))) == b"\xff" + bytes(range(1, 255))
    assert cobs_encode(bytes(range(1, 256))) == b"\xff" + bytes(range(1, 255)) + b"\x02\xff"


@given(st.binary(min_size=2, max_size=62))
def test_any_body_up_to_the_limit_survives_framing(body: bytes) -> None:
    frame = encode_frame(body)
    assert frame.endswith(b"\x00") and 0 not in frame[:-1]
    assert check_block(frame[:-1]) == body


@given(st.binary(min_size=63, max_size=300))
def test_longer_bodies_are_too_long(body: bytes) -> None:
    frame = encode_frame(body)
    assert check_block(frame[:-1]) == ErrorCode.FRAME_TOO_LONG
    assert [type(x) for x in FrameSplitter().feed(frame)] == [FramingError]


def test_splitter_memory_stays_bounded_on_endless_garbage() -> None:
    splitter = FrameSplitter()
    for _ in range(1000):
        assert splitter.feed(bytes(range(1, 256))) == []
    assert len(splitter._pending) <= 67
    out = splitter.feed(b"\x00" + encode(Identify(), 5))
    assert isinstance(out[0], FramingError) and out[0].code == ErrorCode.FRAME_TOO_LONG
    assert out[1] == bytes([0x01, 5])


def test_empty_frames_are_ignored_and_garbage_costs_one_frame() -> None:
    decoder = Decoder("to_firmware")
    good = encode(Identify(), 9)
    items = decoder.feed(b"\x00\x00\x00" + b"\x13\x37" + b"\x00" + good + b"\x00\x00" + good)
    assert items[1:] == [Frame(9, Identify()), Frame(9, Identify())]
    assert isinstance(items[0], DecodeError) and items[0].code == ErrorCode.BAD_COBS


def test_corrupting_any_single_byte_never_yields_a_wrong_frame() -> None:
    """A flipped bit anywhere is caught (CRC, COBS or length) or cuts the frame; it never decodes to another message."""
    seg = Segment(n=700, axes=(AxisMove(axis=1, direction=-1, v0=1000, vn=3000, r=-5),))
    frame = encode(seg, 77)
    for i in range(len(frame) - 1):
        for bit in range(8):
            damaged = bytearray(frame)
            damaged[i] ^= 1 << bit
            for item in Decoder("to_firmware").feed(bytes(damaged)):
                assert isinstance(item, DecodeError), (i, bit, item)


def test_crc_is_little_endian_on_the_wire() -> None:
    body = bytes([0x02, 0x07])
    assert cobs_decode(encode_frame(body)[:-1]) == body + struct.pack("<H", crc16(body))
