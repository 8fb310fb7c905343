"""The link when the other end stops answering or goes away (the real emulator, paused or killed)."""

from __future__ import annotations

import asyncio
import os
import random
import signal
import time

import pytest
from host_helpers import random_segments

from quadstep.kernel.engine_model import predict
from quadstep.link import AlarmError, BoardSilent, FirmwareError, Link, LinkError, LinkTimeout
from quadstep.protocol import POSITION_MAX, Segment, SetPosition, State
from quadstep.kernel.fixed import D
from quadstep.kernel.motion import AxisMove

SEGMENT = Segment(n=100, axes=(AxisMove(axis=0, direction=1, v0=4096, vn=0, r=0),))


def test_a_silent_board_ends_the_link_and_what_it_got_ran_once(start_emulator) -> None:
    """A board that stops answering (SIGSTOP) while a frame waits: resent with a short timeout, then BoardSilent
    (the link is closed; every call says so at once). Once it runs again the copies are duplicates: the segment
    ran once."""
    emu = start_emulator(free=True)
    link = Link.open(emu.url, rto=0.05, retries=3, request_timeout=0.1)
    os.kill(emu.pid, signal.SIGSTOP)
    try:
        start = time.monotonic()
        link.send(SEGMENT)
        with pytest.raises(BoardSilent, match="has not answered for 1.5 s.*last frame it confirmed was seq"):
            link.drain(timeout=10)
        assert time.monotonic() - start < 2.0
        assert link.stats.retransmits >= 3
        with pytest.raises(BoardSilent):
            link.status()
    finally:
        os.kill(emu.pid, signal.SIGCONT)
        link.close()
    with Link.open(emu.url) as again:
        status = again.status()
        for _ in range(100):
            if status.segments_done == 1 and status.state == State.IDLE:
                break
            status = again.status()
        assert status.seq_dup == link.stats.retransmits and status.segments_done == 1 and status.position[0] == 50
        again.send(SEGMENT)
        assert again.wait_idle(timeout=10).position[0] == 100


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


def test_an_unanswered_request_names_the_last_position_and_alarm_known(start_emulator) -> None:
    emu = start_emulator(free=True)
    with Link.open(emu.url, request_timeout=0.05) as link:
        link.send(SetPosition(positions={1: POSITION_MAX}))
        link.send(Segment(n=100, axes=(AxisMove(axis=1, direction=1, v0=D, vn=0, r=0),)))  # past POSITION_MAX
        with pytest.raises((AlarmError, FirmwareError)):
            link.wait_idle(timeout=10)
        at = list(link.status().position)  # the board halted there, in ALARM
        os.kill(emu.pid, signal.SIGSTOP)
        try:
            with pytest.raises(LinkTimeout) as raised:
                link.status()
        finally:
            os.kill(emu.pid, signal.SIGCONT)
    text = str(raised.value)
    assert text.startswith("no answer to STATUS after 8 tries of 0.05 s")
    assert f"(last known state ALARM, position {at} steps, 0 segments done" in text
    assert f"; last alarm REJECTED_SEGMENT at positions {at})" in text
