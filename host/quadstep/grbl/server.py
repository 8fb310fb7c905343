"""Serving GRBL on a pseudo-terminal (a sender opens its path like a serial port) and, if asked, on
TCP 127.0.0.1 (one client at a time: a second is told so and closed)."""

from __future__ import annotations

import os
import select
import socket
import threading
import time
import tty
from collections.abc import Callable
from pathlib import Path

from ..machine import Machine
from .outbox import SenderPort
from .protocol import SOFT_RESET
from .session import Session, SessionOptions

POLL_MS = 100
OPEN_SETTLE_S = 0.2
BUSY = b"[MSG:quadstep: another sender is connected; one at a time]\r\n"


class PtyServer:
    """A pseudo-terminal whose other end is GRBL; `path` is what a sender opens. A sender opening it
    gets a session of its own (the banner after OPEN_SETTLE_S, once the sender has flushed its input
    as serial ports do on opening); closing it ends the session (what moves comes to rest)."""

    def __init__(
        self, machine: Machine, link: Path | None = None, options: SessionOptions | None = None
    ) -> None:
        self.machine = machine
        self.options = options if options is not None else SessionOptions.of(machine)  # shared: $10
        self._master, slave = os.openpty()
        os.set_blocking(self._master, False)
        tty.setraw(slave)
        self.path = Path(os.ttyname(slave))
        os.close(slave)  # nobody has it open: the master reads POLLHUP until a sender opens it
        self.link = link
        if link is not None:
            if link.exists() and not link.is_symlink():
                os.close(self._master)
                raise FileExistsError(f"--link {link}: a file is there already (not a link)")
            if link.is_symlink():
                link.unlink()  # left by an earlier run
            link.symlink_to(self.path)
        self._stop = threading.Event()
        self.session: Session | None = None
        self.connected = threading.Event()

    def _send_now(self, data: bytes) -> int:
        """What of `data` the pseudo-terminal takes now (the master is non-blocking)."""
        return os.write(self._master, data)

    def _send(self, data: bytes) -> None:
        """All of `data` to the sender (the session's writer thread): waits for room while the
        sender reads nothing, and gives up once it has gone."""
        left = memoryview(data)
        room = select.poll()
        room.register(self._master, select.POLLOUT)
        while left:
            try:
                left = left[os.write(self._master, left) :]
                continue
            except BlockingIOError:
                pass
            events = room.poll(POLL_MS)
            if self._stop.is_set() or any(flags & select.POLLHUP for _, flags in events):
                raise BrokenPipeError("the sender has closed the port")

    def serve(self) -> None:
        """Until stop(): a session for each sender that opens the path, its bytes to it."""
        poller = select.poll()
        poller.register(self._master, select.POLLIN)
        while not self._stop.is_set():
            events = poller.poll(POLL_MS)
            if any(flags & select.POLLHUP for _, flags in events):
                self._hang_up()
                time.sleep(POLL_MS / 1000)
                continue
            first = self.session is None
            if first:
                time.sleep(OPEN_SETTLE_S)
            try:
                data = os.read(self._master, 4096) if events or first else b""
            except BlockingIOError:
                data = b""
            except OSError:
                continue  # closed between poll and read: the next poll says so
            if (
                self.session is None
            ):  # a soft reset sent on opening (as senders do) brings the banner
                port = SenderPort(self._send_now, self._send)
                self.session = Session(self.machine, port, self.options).start(
                    SOFT_RESET not in data
                )
                self.connected.set()
            self.session.receive(data)
        self._hang_up()

    def _hang_up(self) -> None:
        if self.session is not None:
            self.session.close()
            self.session = None
            self.connected.clear()

    def stop(self) -> None:
        self._stop.set()

    def close(self) -> None:
        self._hang_up()
        if self.link is not None and self.link.is_symlink():
            self.link.unlink()
        os.close(self._master)


class TcpServer:
    """GRBL on 127.0.0.1:`port` (0: any free port, then `port` says which), one client at a time."""

    def __init__(
        self,
        machine: Machine,
        port: int,
        on_client: Callable[[str], None] | None = None,
        options: SessionOptions | None = None,
    ) -> None:
        self.machine = machine
        self.options = options if options is not None else SessionOptions.of(machine)  # shared: $10
        self._socket = socket.create_server(("127.0.0.1", port))
        self.port = self._socket.getsockname()[1]
        self.on_client = on_client
        self._lock = threading.Lock()
        self._client: socket.socket | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, name="grbl-tcp", daemon=True)

    def start(self) -> TcpServer:
        self._thread.start()
        return self

    def _accept(self) -> None:
        self._socket.settimeout(0.2)
        while not self._stop.is_set():
            try:
                client, address = self._socket.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            with self._lock:
                busy = self._client is not None
                if not busy:
                    self._client = client
            if busy:
                client.sendall(BUSY)
                client.close()
                continue
            if self.on_client is not None:
                self.on_client(f"{address[0]}:{address[1]}")
            threading.Thread(
                target=self._serve, args=(client,), name="grbl-client", daemon=True
            ).start()

    def _serve(self, client: socket.socket) -> None:
        port = SenderPort(lambda data: client.send(data, socket.MSG_DONTWAIT), client.sendall)
        session = Session(self.machine, port, self.options).start()
        try:
            while not self._stop.is_set():
                ready, _, _ = select.select([client], [], [], 0.2)
                if not ready:
                    continue
                data = client.recv(4096)
                if not data:
                    break
                session.receive(data)
        except OSError:
            pass
        finally:
            try:
                client.shutdown(socket.SHUT_RDWR)  # the session's writer never waits on it again
            except OSError:
                pass  # gone already
            session.close()
            client.close()
            with self._lock:
                self._client = None

    def close(self) -> None:
        self._stop.set()
        self._socket.close()
        self._thread.join(timeout=5)
