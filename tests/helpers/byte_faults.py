"""A noisy serial line between the host and a board: a byte-level proxy on pseudo-terminals.

The host opens `FaultyLine.port` (a pseudo-terminal) as it would a board; every byte it writes reaches the
board's port (the emulator's pseudo-terminal) and every byte back reaches the host, each direction paced at
`baud` (10 bits a byte, as a UART line) and, at a rate of `p` per byte, damaged in one of four ways chosen
alike: a bit flipped, the byte dropped, the byte doubled, a random byte inserted before it. Nothing here knows
the protocol: whatever the link and the firmware make of a damaged frame is theirs.
"""

from __future__ import annotations

import os
import threading
import time
import tty
from dataclasses import dataclass, field

import numpy as np

FAULTS = ("flip", "drop", "duplicate", "insert")


@dataclass
class Direction:
    """What one direction of the line carried and did to it."""

    bytes_in: int = 0
    bytes_out: int = 0
    faults: dict[str, int] = field(default_factory=lambda: dict.fromkeys(FAULTS, 0))


class FaultyLine:
    """Relays host <-> board through a pseudo-terminal pair, damaging bytes at rate `p` in both directions."""

    def __init__(self, board_port: str, p: float, *, baud: int = 500_000, seed: int = 1) -> None:
        self.p = p
        self.byte_time = 10.0 / baud
        self.to_board = Direction()
        self.to_host = Direction()
        self._rng = np.random.default_rng(seed)
        self._rng_lock = threading.Lock()
        self._master, slave = os.openpty()
        tty.setraw(slave)
        self.port = os.ttyname(slave)
        self._slave = slave  # kept open so the host can close and open the port again
        self._board = os.open(board_port, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self._board)
        self._closed = threading.Event()
        self._threads = [
            threading.Thread(target=self._relay, args=(self._master, self._board, self.to_board), daemon=True),
            threading.Thread(target=self._relay, args=(self._board, self._master, self.to_host), daemon=True),
        ]
        for thread in self._threads:
            thread.start()

    def close(self) -> None:
        self._closed.set()
        for fd in (self._master, self._slave, self._board):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self) -> FaultyLine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def faults(self) -> int:
        return sum(self.to_board.faults.values()) + sum(self.to_host.faults.values())

    def damage(self, data: bytes, counts: Direction) -> bytes:
        """`data` as the line delivers it: each byte damaged with probability p."""
        if self.p <= 0:
            return data
        with self._rng_lock:
            hit = np.flatnonzero(self._rng.random(len(data)) < self.p)
            if not hit.size:
                return data
            kinds = self._rng.integers(0, len(FAULTS), hit.size)
            values = self._rng.integers(0, 256, hit.size)
            bits = self._rng.integers(0, 8, hit.size)
        out = bytearray()
        start = 0
        for at, kind, value, bit in zip(hit.tolist(), kinds.tolist(), values.tolist(), bits.tolist()):
            out += data[start:at]
            byte = data[at]
            name = FAULTS[kind]
            counts.faults[name] += 1
            if name == "flip":
                out.append(byte ^ (1 << bit))
            elif name == "duplicate":
                out += bytes((byte, byte))
            elif name == "insert":
                out += bytes((value, byte))
            start = at + 1  # a dropped byte adds nothing
        out += data[start:]
        return bytes(out)

    def _relay(self, source: int, sink: int, counts: Direction) -> None:
        """Read what arrives, damage it, deliver it no faster than the line's rate."""
        free_at = time.monotonic()  # when the line has sent everything so far
        while not self._closed.is_set():
            try:
                data = os.read(source, 4096)
            except OSError:
                if self._closed.is_set():
                    return
                time.sleep(0.01)  # no one on that end yet (EIO until the host opens its port)
                continue
            if not data:
                time.sleep(0.001)
                continue
            counts.bytes_in += len(data)
            out = self.damage(data, counts)
            free_at = max(free_at, time.monotonic()) + len(out) * self.byte_time
            wait = free_at - time.monotonic()
            if wait > 0:
                time.sleep(wait)  # the last byte is off the wire
            try:
                os.write(sink, out)
            except OSError:
                if self._closed.is_set():
                    return
                continue
            counts.bytes_out += len(out)
