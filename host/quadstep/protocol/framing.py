"""Framing (PROTOCOL.md §2): COBS(body ‖ crc16) ‖ 0x00, and its streaming decoder.

COBS is written here rather than taken from a package because the receiver
must classify bad input exactly as the firmware does (too long before bad COBS
before too short), which needs the decoded byte count of invalid blocks too.
"""

from __future__ import annotations

import binascii
import struct
from dataclasses import dataclass

from .constants import BROADCAST_SEQ, DELIMITER, MAX_FRAME, MIN_FRAME, ErrorCode

# A raw block this long always decodes to more than MAX_FRAME bytes: every code
# byte but the first adds a zero unless it follows a full 254-byte group.
_SURELY_TOO_LONG = MAX_FRAME + 3


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF)."""
    return binascii.crc_hqx(data, 0xFFFF)


def cobs_encode(block: bytes) -> bytes:
    """Standard COBS: the result holds no zero byte."""
    out = bytearray()
    start = 0
    while True:
        zero = block.find(0, start, start + 254)
        if zero < 0:
            run = block[start : start + 254]
            if len(run) == 254 and start + 254 < len(block):
                out += b"\xff" + run
                start += 254
                continue
            out += bytes([len(run) + 1]) + run
            return bytes(out)
        out += bytes([zero - start + 1]) + block[start:zero]
        start = zero + 1


def encode_frame(body: bytes) -> bytes:
    """The wire bytes of one frame, delimiter included."""
    return cobs_encode(body + struct.pack("<H", crc16(body))) + b"\x00"


@dataclass(frozen=True)
class FramingError:
    """A frame rejected before its type could be trusted (codes 1–5 of §2)."""

    code: ErrorCode
    raw: bytes  # the bytes received for this frame, delimiter excluded (truncated when too long)


def cobs_decode(raw: bytes) -> bytes | ErrorCode:
    """Decode one block (no delimiter) into body ‖ crc, or the framing error it earns."""
    out = bytearray()
    pos = 0
    end = len(raw)
    while pos < end:
        code = raw[pos]
        stop = pos + code
        out += raw[pos + 1 : stop]
        if len(out) > MAX_FRAME:
            return ErrorCode.FRAME_TOO_LONG
        if stop > end:
            return ErrorCode.BAD_COBS
        if code < 0xFF and stop < end:
            out.append(0)
            if len(out) > MAX_FRAME:
                return ErrorCode.FRAME_TOO_LONG
        pos = stop
    return bytes(out)


def check_block(raw: bytes) -> bytes | ErrorCode:
    """body (type, seq, payload) of a received block, or its framing error, in the order of §2."""
    if len(raw) >= _SURELY_TOO_LONG:
        return ErrorCode.FRAME_TOO_LONG
    decoded = cobs_decode(raw)
    if isinstance(decoded, ErrorCode):
        return decoded
    if len(decoded) < MIN_FRAME:
        return ErrorCode.FRAME_TOO_SHORT
    body, crc = decoded[:-2], struct.unpack("<H", decoded[-2:])[0]
    if crc16(body) != crc:
        return ErrorCode.BAD_CRC
    return body


class FrameSplitter:
    """Cuts a byte stream at delimiters; yields each checked body or a FramingError.

    Empty frames (two delimiters in a row) are skipped silently. A block that
    grows past any possible frame is dropped until the next delimiter, so
    memory stays bounded whatever arrives.
    """

    def __init__(self) -> None:
        self._pending = bytearray()
        self._overlong = False

    def feed(self, data: bytes) -> list[bytes | FramingError]:
        out: list[bytes | FramingError] = []
        start = 0
        while True:
            end = data.find(DELIMITER, start)
            if end < 0:
                self._keep(data[start:])
                return out
            self._keep(data[start:end])
            raw = bytes(self._pending)
            overlong = self._overlong
            self._pending.clear()
            self._overlong = False
            start = end + 1
            if overlong:
                out.append(FramingError(ErrorCode.FRAME_TOO_LONG, raw))
            elif raw:
                checked = check_block(raw)
                out.append(
                    FramingError(checked, raw) if isinstance(checked, ErrorCode) else checked
                )

    def _keep(self, chunk: bytes) -> None:
        if self._overlong:
            return
        self._pending += chunk
        if len(self._pending) >= _SURELY_TOO_LONG:
            self._overlong = True
            del self._pending[_SURELY_TOO_LONG:]


__all__ = [
    "BROADCAST_SEQ",
    "FramingError",
    "FrameSplitter",
    "check_block",
    "cobs_decode",
    "cobs_encode",
    "crc16",
    "encode_frame",
]
