"""The port and its two threads: a reader that hands every chunk received to the link and at once
writes what that chunk made due (a frame whose queue slots a report has just freed), and a writer
that writes whatever else the link has to send. Nothing here knows the protocol."""

from __future__ import annotations

import gc
import sys
import threading
from collections.abc import Callable

import serial

from .errors import HEARD_BYTES

# The interpreter hands over to a thread that waits for it every millisecond rather than every five
# (Python's default), so that the reader runs within a millisecond or two of a report while other
# threads plan: a board's queue of short segments lasts about ten.
SWITCH_INTERVAL_S = 0.001

# What pyserial raises once the port is gone (TypeError and AttributeError from a port closed under
# it).
PORT_FAILURES = (serial.SerialException, OSError, TypeError, AttributeError)


def favour_the_link() -> None:
    """Set this program's interpreter for streaming to a board (the command line does, once its
    modules are loaded): the switch interval above, and what is alive now (the modules, their
    classes and schemas, tens of thousands of objects that live as long as the program) moved out
    of the garbage collector's reach, so that a full collection, which stops every thread, walks
    only what came after (it took 65–110 ms in a busy streaming bench, 11–42 ms so)."""
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    gc.freeze()


class Transport:
    """Runs the reader and the writer on `port` until close().

    `on_look()` is called in the reader as it begins each read (which waits up to the port's
    timeout), `on_data(bytes)` for every chunk read, then `output_now()` with `cond` held for the
    bytes to write now (b"" for none); `next_output()` is called in the writer with `cond` held,
    waits on `writable` (a condition on the same lock) for something to write and returns the
    bytes, or None once `closed`; `on_failure(exc)` gets the first exception of the port, in
    either thread. Whatever either thread takes under `cond` goes out in the order taken.
    """

    def __init__(
        self,
        port: serial.SerialBase,
        cond: threading.Condition,
        writable: threading.Condition,
        on_look: Callable[[], None],
        on_data: Callable[[bytes], None],
        next_output: Callable[[], bytes | None],
        on_failure: Callable[[Exception], None],
        output_now: Callable[[], bytes],
    ) -> None:
        self.port = port
        self.cond = cond
        self.writable = writable
        self.closed = False  # guarded by cond
        # the first bytes read (HEARD_BYTES), to name a board that answers in another's text
        self.heard = b""
        self._on_look = on_look
        self._on_data = on_data
        self._next_output = next_output
        self._on_failure = on_failure
        self._output_now = output_now
        # taken with cond held, so that chunks go out in the order they were taken
        self._write_lock = threading.Lock()
        self._threads = [
            threading.Thread(target=self._read_loop, name="quadstep-link-reader", daemon=True),
            threading.Thread(target=self._write_loop, name="quadstep-link-writer", daemon=True),
        ]

    def start(self) -> None:
        for thread in self._threads:
            thread.start()

    def close(self) -> None:
        with self.cond:
            self.closed = True
            self.cond.notify_all()
            self.writable.notify_all()
        for thread in self._threads:
            if thread.is_alive() and thread is not threading.current_thread():
                thread.join(timeout=2)
        self.port.close()

    def _read_loop(self) -> None:
        while not self.closed:
            self._on_look()
            try:
                data = self.port.read(self.port.in_waiting or 1)
            except PORT_FAILURES as exc:
                self._on_failure(exc)
                return
            if data:
                if len(self.heard) < HEARD_BYTES:
                    self.heard += data[: HEARD_BYTES - len(self.heard)]
                self._on_data(data)
                # written here rather than by waking the writer: the board waits on it, and each
                # thread that must run first may wait for its turn in the interpreter
                with self.cond:
                    chunk = self._output_now()
                    if chunk:
                        self._write_lock.acquire()
                if chunk and not self._write(chunk):
                    return

    def _write_loop(self) -> None:
        while True:
            with self.cond:
                chunk = self._next_output()
                if chunk is not None:
                    self._write_lock.acquire()
            if chunk is None:
                return
            if not self._write(chunk):
                return

    def _write(self, chunk: bytes) -> bool:
        try:
            self.port.write(chunk)
        except PORT_FAILURES as exc:
            self._on_failure(exc)
            return False
        finally:
            self._write_lock.release()
        return True
