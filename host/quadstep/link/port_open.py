"""Opening the serial port without resetting the board.

An Uno (and most Arduino boards) resets when DTR is asserted: the USB
serial chip's DTR line reaches RESET through a capacitor. Linux drops DTR
when a port is closed (the HUPCL flag) and asserts it again when the port
is opened, so every new connection would reset the board — and lose its
position and a job in the middle of its queue. Once the port is open,
quadstep clears HUPCL: DTR then stays asserted after the port is closed,
and opening it again changes nothing on the line. The first connection
after the board is plugged in still resets it (DTR rises then), which is
harmless at rest.
"""

from __future__ import annotations

import termios

import serial

READ_TIMEOUT = 0.05  # s a read of the port waits for a byte: the reader looks at least this often


def keep_dtr(port: serial.SerialBase) -> None:
    """Clear HUPCL on an open local port, so closing it leaves DTR asserted (no reset at the next
    open)."""
    try:
        fd = port.fileno()
    except (AttributeError, serial.SerialException, OSError, ValueError):
        return  # socket:// and other URLs have no terminal
    try:
        attributes = termios.tcgetattr(fd)
        if attributes[2] & termios.HUPCL:
            attributes[2] &= ~termios.HUPCL
            termios.tcsetattr(fd, termios.TCSANOW, attributes)
    except termios.error:
        return  # not a terminal


def open_port(url: str, baudrate: int) -> serial.SerialBase:
    """The port at `url` opened for the link, its DTR kept across closing (see above)."""
    port = serial.serial_for_url(url, baudrate=baudrate, timeout=READ_TIMEOUT, write_timeout=10)
    keep_dtr(port)
    return port
