"""Connecting: refusals the real firmware cannot provoke (silence, another protocol version).

Both run on a real pseudo-terminal through pyserial. A silent line needs no
other end; no firmware of another protocol version exists, so a few lines
answer IDENTIFY the way one would.
"""

from __future__ import annotations

import os
import struct
import threading
import tty
from collections.abc import Callable, Iterator

import pytest

from quadstep.link import Link, LinkError, LinkTimeout, ProtocolVersionError
from quadstep.protocol import Decoder, Frame, Identify, IdentifyReply, encode
from quadstep.protocol.framing import encode_frame


@pytest.fixture
def pty() -> Iterator[tuple[int, str]]:
    """(master fd, slave path); the slave stays open so the master never reads EIO."""
    master, slave = os.openpty()
    tty.setraw(slave)
    yield master, os.ttyname(slave)
    os.close(slave)
    os.close(master)


def test_silent_line_times_out_with_a_clear_message(pty: tuple[int, str]) -> None:
    master, path = pty
    with pytest.raises(LinkTimeout, match=r"no answer to IDENTIFY after 3 tries of 0.1 s"):
        Link.open(path, retries=3, request_timeout=0.1)
    sent = os.read(master, 4096)
    frames = Decoder("to_firmware").feed(sent)
    assert sent.startswith(b"\x00") and len(frames) == 3
    assert all(isinstance(f, Frame) and f.message == Identify() for f in frames)
    assert len({f.seq for f in frames if isinstance(f, Frame)}) == 1  # resends of one request


def _answer_identify(master: int, stop: threading.Event, reply: Callable[[int], bytes]) -> None:
    """A firmware that answers IDENTIFY with reply(seq) and nothing else."""
    decoder = Decoder("to_firmware")
    while not stop.is_set():
        try:
            data = os.read(master, 256)
        except OSError:
            return
        for item in decoder.feed(data):
            if isinstance(item, Frame) and isinstance(item.message, Identify):
                os.write(master, reply(item.seq))


def test_unknown_protocol_version_is_refused_naming_both(pty: tuple[int, str]) -> None:
    master, path = pty
    stop = threading.Event()
    reply = IdentifyReply(
        protocol_version=4, fw_major=9, fw_minor=0, fw_patch=0, board=0, axis_count=4,
        queue_capacity=8, speed_shift=12, n_max=1022, tick_hz=50000, capabilities=3,
        next_seq=0, boot_id=7,
    )
    responder = threading.Thread(target=_answer_identify, args=(master, stop, lambda seq: encode(reply, seq)),
                                 daemon=True)
    responder.start()
    try:
        with pytest.raises(ProtocolVersionError, match="protocol version 4; this host speaks version 3"):
            Link.open(path, request_timeout=0.5)
    finally:
        stop.set()


@pytest.mark.parametrize("version, payload", [
    (1, struct.pack("<BBBBBBBBHIHB", 1, 0, 1, 0, 0, 4, 32, 12, 1022, 50000, 3, 0)),
    (2, struct.pack("<BBBBBBBBHIHBH", 2, 0, 1, 0, 0, 4, 32, 12, 1022, 50000, 3, 0, 7)),
])
def test_an_older_board_is_named_as_another_protocol_version(pty: tuple[int, str], version: int,
                                                              payload: bytes) -> None:
    """Version 1's IDENTIFY_REPLY had 17 bytes (no boot_id), version 2's 19 (no raster_ring): neither
    decodes, and the host says why at once."""
    master, path = pty
    stop = threading.Event()

    def older(seq: int) -> bytes:
        return encode_frame(bytes([0x81, seq]) + payload)

    responder = threading.Thread(target=_answer_identify, args=(master, stop, older), daemon=True)
    responder.start()
    try:
        match = f"{len(payload)}-byte payload.*another protocol version than this host's 3"
        with pytest.raises(ProtocolVersionError, match=match):
            Link.open(path, request_timeout=5.0, retries=1)
    finally:
        stop.set()


def test_missing_port_is_a_link_error() -> None:
    with pytest.raises(LinkError, match="cannot open /dev/nonexistent-quadstep"):
        Link.open("/dev/nonexistent-quadstep")
