"""The host's decoder under fuzzed input (hypothesis), both directions: random bytes, and the protocol vectors'
frames flipped, cut, doubled, spliced. Whatever arrives, the decoder returns frames or DecodeErrors (never raises),
every frame it returns encodes back to the same message, and its memory stays bounded."""

from __future__ import annotations

import json
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from quadstep.protocol import DecodeError, Decoder, Frame, encode
from quadstep.protocol.framing import _SURELY_TOO_LONG

REPO = Path(__file__).resolve().parents[2]
VECTORS = json.loads((REPO / "protocol" / "vectors.json").read_text())["vectors"]
FRAMES = [bytes.fromhex(v["frame"]) for v in VECTORS]


@st.composite
def damaged_streams(draw: st.DrawFn) -> bytes:
    """A stream of vector frames, each possibly damaged: a bit flipped, a byte dropped, doubled or inserted,
    cut short, or followed by garbage."""
    out = bytearray()
    for frame in draw(st.lists(st.sampled_from(FRAMES), min_size=1, max_size=8)):
        data = bytearray(frame)
        for _ in range(draw(st.integers(0, 3))):
            at = draw(st.integers(0, len(data) - 1))
            kind = draw(st.sampled_from(["flip", "drop", "double", "insert", "cut"]))
            if kind == "flip":
                data[at] ^= 1 << draw(st.integers(0, 7))
            elif kind == "drop" and len(data) > 1:
                del data[at]
            elif kind == "double":
                data.insert(at, data[at])
            elif kind == "insert":
                data.insert(at, draw(st.integers(0, 255)))
            elif kind == "cut":
                del data[at:]
                break
        out += data
        out += draw(st.binary(max_size=4))
    return bytes(out)


def check(stream: bytes, direction: str, chunk: int) -> None:
    decoder = Decoder(direction)  # type: ignore[arg-type]
    for start in range(0, len(stream), chunk):
        for item in decoder.feed(stream[start:start + chunk]):
            assert isinstance(item, (Frame, DecodeError))
            if isinstance(item, Frame):
                again = Decoder(direction).feed(encode(item.message, item.seq))  # type: ignore[arg-type]
                assert len(again) == 1 and isinstance(again[0], Frame) and again[0].message == item.message
        assert len(decoder._splitter._pending) <= _SURELY_TOO_LONG  # bounded, whatever arrives


@settings(max_examples=600, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(damaged_streams(), st.sampled_from(["to_host", "to_firmware"]), st.integers(1, 70))
def test_damaged_vector_frames_decode_or_fail_cleanly(stream: bytes, direction: str, chunk: int) -> None:
    check(stream, direction, chunk)


@settings(max_examples=400, deadline=None)
@given(st.binary(max_size=600), st.sampled_from(["to_host", "to_firmware"]), st.integers(1, 70))
def test_random_bytes_decode_or_fail_cleanly(stream: bytes, direction: str, chunk: int) -> None:
    check(stream, direction, chunk)
