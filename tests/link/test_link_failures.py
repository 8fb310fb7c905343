"""The link when the other end stops answering or goes away (the real emulator, paused or killed)."""

from __future__ import annotations

import asyncio
import os
import random
import signal

import pytest
from host_helpers import random_segments

from quadstep.engine_model import predict
from quadstep.link import Link, LinkError, LinkTimeout
from quadstep.protocol import AxisMove, Segment, State

SEGMENT = Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=4096, vn=0, r=0),))


def test_unacknowledged_frame_gives_up_after_its_resends(start_emulator) -> None:
    emu = start_emulator(free=True)
    with Link.open(emu.url, rto=0.05, retries=3, request_timeout=0.1) as link:
        os.kill(emu.pid, signal.SIGSTOP)
        try:
            link.send(SEGMENT)
            with pytest.raises(LinkTimeout, match="frame seq .* unacknowledged after 3 resends"):
                link.drain(timeout=10)
            assert link.stats.retransmits == 3
            with pytest.raises(LinkTimeout, match="no answer to STATUS after 3 tries"):
                link.status()
        finally:
            os.kill(emu.pid, signal.SIGCONT)
        # The firmware now reads the four copies: one executes, three are duplicates. (A STOP sent now
        # could arrive in the same read as the copies and flush the segment before its first tick.)
        status = link.status()
        for _ in range(100):
            if status.segments_done == 1 and status.state == State.IDLE:
                break
            status = link.status()
        assert status.seq_dup == 3 and status.segments_done == 1 and status.position[0] == 50
        assert link.stop().state == State.IDLE
        link.send(SEGMENT)
        assert link.wait_idle(timeout=10).position[0] == 100


def test_emulator_gone_is_a_link_error(start_emulator) -> None:
    emu = start_emulator(free=True)
    with Link.open(emu.url, request_timeout=0.2, retries=2) as link:
        os.kill(emu.pid, signal.SIGKILL)
        with pytest.raises(LinkError):
            for _ in range(100):
                link.status()


async def test_usable_from_asyncio_threads_while_another_thread_streams(start_emulator) -> None:
    emu = start_emulator(free=True)
    segments = random_segments(random.Random(11), 200)
    link = await asyncio.to_thread(Link.open, emu.url)
    try:

        def stream() -> None:
            for seg in segments:
                link.send(seg)

        async def poll() -> int:
            polls = 0
            while not sending.done():
                status = await asyncio.to_thread(link.status)
                assert status.state in (State.IDLE, State.RUNNING)
                polls += 1
            return polls

        sending = asyncio.ensure_future(asyncio.to_thread(stream))
        polls = await poll()
        await sending
        final = await asyncio.to_thread(link.wait_idle, 30)
        assert polls >= 1
        assert list(final.position) == predict(segments).positions and final.segments_done == 200
    finally:
        await asyncio.to_thread(link.close)
