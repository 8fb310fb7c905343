"""Reopening the port leaves DTR as it was (an Uno resets when DTR is asserted anew): the link clears HUPCL on
the terminal, so closing it does not drop DTR, and a board in the middle of a job survives a reconnect."""

from __future__ import annotations

import os
import termios

from quadstep.link import Link


def hupcl(path: str) -> bool:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    try:
        return bool(termios.tcgetattr(fd)[2] & termios.HUPCL)
    finally:
        os.close(fd)


def test_the_link_leaves_the_port_without_hangup_on_close(start_emulator) -> None:
    emu = start_emulator(axes=3)
    fd = os.open(emu.url, os.O_RDWR | os.O_NOCTTY)  # as a fresh terminal has it: hang up on close
    attributes = termios.tcgetattr(fd)
    attributes[2] |= termios.HUPCL
    termios.tcsetattr(fd, termios.TCSANOW, attributes)
    os.close(fd)
    assert hupcl(emu.url)
    with Link.open(emu.url) as link:
        first = link.identify()
    assert not hupcl(emu.url)
    with Link.open(emu.url) as link:  # opened again: the same board, not reset
        assert link.identify() == first
