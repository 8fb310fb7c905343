"""The host codec against every vector of protocol/vectors.json, both ways."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from pydantic import BaseModel

from quadstep.protocol import PROTOCOL_VERSION, DecodeError, Decoder, Frame, decode, encode
from quadstep.protocol.constants import ErrorCode, FieldId
from quadstep.protocol.framing import cobs_decode
from quadstep.protocol.messages import MessageType, message_from_json
from quadstep.protocol.raster import Raster, line_fault

REPO = Path(__file__).resolve().parents[2]
VECTORS_FILE = REPO / "protocol" / "vectors.json"
DOC = json.loads(VECTORS_FILE.read_text())
VECTORS = DOC["vectors"]
VALID = [v for v in VECTORS if v["message"] is not None]
MALFORMED = [v for v in VECTORS if v["error"] is not None]


def as_message(vector: dict) -> tuple[int, BaseModel]:
    return message_from_json(vector["message"])


def test_committed_file_is_the_generators_output() -> None:
    generator = REPO / "protocol" / "make_vectors.py"
    result = subprocess.run([sys.executable, str(generator), "--check"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_the_vectors_are_for_the_hosts_protocol_version() -> None:
    assert DOC["protocol_version"] == PROTOCOL_VERSION


def test_vectors_cover_every_message_error_and_field() -> None:
    valid_types = {v["message"]["type"] for v in VALID}
    assert valid_types == {t.name for t in MessageType}
    error_codes = {v["error"]["code"] for v in MALFORMED}
    assert error_codes == {c.name for c in ErrorCode} - {"RX_OVERRUN", "BUSY", "ALARM_ACTIVE", "INPUT_AT_LEVEL"}
    assert {v["error"]["field"] for v in MALFORMED if v["error"]["field"]} == {f.name for f in FieldId}
    reported = {v["message"]["code"] for v in VALID if v["message"]["type"] == "ERROR"}
    assert reported == {c.name for c in ErrorCode}
    reasons = {v["message"]["reason"] for v in VALID if v["message"]["type"] == "ACK"}
    assert reasons == {"ACCEPTED", "GAP", "DUPLICATE", "QUEUE_FULL", "REJECTED", "SPACE", "PARKED"}
    status_axes = {len(v["message"]["position"]) for v in VALID if v["message"]["type"] == "STATUS_REPORT"}
    assert {3, 4} <= status_axes
    assert {len(v["message"]["axes"]) for v in VALID if v["message"]["type"] == "SEGMENT"} == {0, 1, 2, 3, 4}


@pytest.mark.parametrize("vector", VALID, ids=[v["name"] for v in VALID])
def test_valid_vector_decodes_and_encodes(vector: dict) -> None:
    frame = bytes.fromhex(vector["frame"])
    seq, message = as_message(vector)
    decoded = decode(frame, vector["direction"], vector.get("axis_count", 4))
    assert decoded == Frame(seq, message)  # type: ignore[arg-type]
    if isinstance(message, Raster):
        assert line_fault(message, *chain_after(vector)) is None
    assert encode(message, seq) == frame  # type: ignore[arg-type]
    assert message.model_dump(mode="json") == {k: v for k, v in vector["message"].items() if k not in ("type", "seq")}


def chain_after(vector: dict) -> tuple[list[int], list[int]]:
    """Speeds and residuals per axis where the vector's SEGMENT before leaves them (at rest without
    one): vn, and the ideal's end less the steps made, in 1/8192 step."""
    speeds, residuals = [0] * 4, [0] * 4
    for ax in vector.get("after", {}).get("axes", []):
        n, v0, vn, r = vector["after"]["n"], ax["v0"], ax["vn"], ax["r"]
        ideal = r + (v0 + vn) * n  # 1/8192 step
        speeds[ax["axis"]] = vn
        residuals[ax["axis"]] = ideal - 8192 * ((ideal + 4096) // 8192)
    return speeds, residuals


CHAIN_FIELDS = ("RASTER_AXIS", "PIXELS")


@pytest.mark.parametrize("vector", MALFORMED, ids=[v["name"] for v in MALFORMED])
def test_malformed_vector_is_refused_with_its_error(vector: dict) -> None:
    frame = bytes.fromhex(vector["frame"])
    if vector["error"]["field"] in CHAIN_FIELDS:
        # what the line says against its chain: the decoder has no chain, line_fault has
        decoded = decode(frame, vector["direction"], vector.get("axis_count", 4))
        assert isinstance(decoded.message, Raster)
        assert line_fault(decoded.message, *chain_after(vector)) == FieldId[vector["error"]["field"]]
        return
    with pytest.raises(DecodeError) as caught:
        decode(frame, vector["direction"], vector.get("axis_count", 4))
    error = caught.value
    got = {"code": error.code.name, "field": error.field.name if error.field else None, "axis": error.axis}
    assert got == vector["error"]
    if error.code in (ErrorCode.UNKNOWN_TYPE, ErrorCode.BAD_LENGTH, ErrorCode.BAD_FIELD):
        assert (error.frame_type, error.frame_seq) == (frame_body_type_seq(frame))
    else:
        assert (error.frame_type, error.frame_seq) == (0xFF, 0xFF)


def frame_body_type_seq(frame: bytes) -> tuple[int, int]:
    body = cobs_decode(frame[:-1])
    assert isinstance(body, bytes)
    return body[0], body[1]


@pytest.mark.parametrize("direction", ["to_firmware", "to_host"])
@pytest.mark.parametrize("chunk", [1, 3, 64, 100_000])
def test_streaming_decoder_on_all_vectors_back_to_back(direction: str, chunk: int) -> None:
    """Every frame of one direction in one stream, cut anywhere: the same results in the same order."""
    vectors = [v for v in VECTORS if v["direction"] == direction and v.get("axis_count", 4) == 4]
    vectors = [v for v in vectors if v["error"] is None or v["error"]["field"] not in CHAIN_FIELDS]
    stream = b"\x00" + b"\x00".join(bytes.fromhex(v["frame"]) for v in vectors)  # plus empty frames
    decoder = Decoder(direction, axis_count=4)  # type: ignore[arg-type]
    items: list[Frame | DecodeError] = []
    for start in range(0, len(stream), chunk):
        items += decoder.feed(stream[start : start + chunk])
    assert len(items) == len(vectors)
    for vector, item in zip(vectors, items):
        if vector["message"] is not None:
            assert item == Frame(*as_message(vector))  # type: ignore[arg-type]
        else:
            assert isinstance(item, DecodeError) and item.code.name == vector["error"]["code"], vector["name"]
