"""The varints of SEGMENTS and CUBIC_SEGMENTS records: 7 bits a byte, lowest first, the top bit set
on every byte but the last; signed values zigzag-coded first (0, −1, 1, −2 … → 0, 1, 2, 3 …) so that
small changes of either sign take one byte (protocol/PROTOCOL.md)."""

from __future__ import annotations


def zigzag(value: int) -> int:
    return value << 1 if value >= 0 else (-value << 1) - 1


def unzigzag(u: int) -> int:
    return (u >> 1) ^ -(u & 1)


def uvarint(u: int) -> bytes:
    out = bytearray()
    while u >= 0x80:
        out.append(u & 0x7F | 0x80)
        u >>= 7
    out.append(u)
    return bytes(out)


def svarint(value: int) -> bytes:
    return uvarint(zigzag(value))


def read_uvarint(payload: bytes, at: int, most: int) -> tuple[int, int] | None:
    """(value, next offset), or None where the payload ends inside it or it runs past `most`
    bytes."""
    u = shift = 0
    for k in range(most):
        if at + k >= len(payload):
            return None
        u |= (payload[at + k] & 0x7F) << shift
        shift += 7
        if not payload[at + k] & 0x80:
            return u, at + k + 1
    return None


def read_svarint(payload: bytes, at: int, most: int) -> tuple[int, int] | None:
    read = read_uvarint(payload, at, most)
    return None if read is None else (unzigzag(read[0]), read[1])
