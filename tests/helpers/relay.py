"""A TCP relay between the host and an emulator served with --tcp: the host's connection stays open while the
emulator behind it is killed and started again on the same port, as a USB serial adapter stays open while the
board behind it resets."""

from __future__ import annotations

import select
import socket
import threading
import time

from quadstep.protocol import Ack, Decoder, Frame, StatusReport


class Relay:
    """Listens on 127.0.0.1 (`.url`); forwards to `target_port`, connecting there again whenever it drops.
    Bytes from the host while no board listens are lost, as they are on a board that resets."""

    def __init__(self, target_port: int) -> None:
        self.target_port = target_port
        self._listen = socket.create_server(("127.0.0.1", 0))
        self._listen.settimeout(60)
        self.url = f"socket://127.0.0.1:{self._listen.getsockname()[1]}"
        self.reconnects = 0  # connections to the board after the first
        self.segments_done = 0  # the most the board has reported done (STATUS_REPORT, ACK), read from the line
        self._decoder = Decoder("to_host")
        self._closed = threading.Event()
        self._thread = threading.Thread(target=self._run, name="relay", daemon=True)

    def __enter__(self) -> Relay:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._closed.set()
        self._thread.join(timeout=5)
        self._listen.close()

    def wait_done(self, segments: int, timeout: float = 60.0) -> None:
        """Until the board has reported `segments` done: the job is well under way."""
        deadline = time.monotonic() + timeout
        while self.segments_done < segments:
            assert time.monotonic() < deadline and self._thread.is_alive(), "the board never got that far"
            self._closed.wait(0.02)

    def _watch(self, data: bytes) -> None:
        for item in self._decoder.feed(data):
            if isinstance(item, Frame) and isinstance(item.message, StatusReport):
                self.segments_done = max(self.segments_done, item.message.segments_done)
            elif isinstance(item, Frame) and isinstance(item.message, Ack):  # SPACE acks count too
                self.segments_done = max(self.segments_done, item.message.done)

    def _board(self) -> socket.socket | None:
        while not self._closed.is_set():
            try:
                return socket.create_connection(("127.0.0.1", self.target_port), timeout=1)
            except OSError:
                self._closed.wait(0.02)  # nobody listens yet: the board is starting again
        return None

    def _run(self) -> None:
        host, _ = self._listen.accept()
        board = self._board()
        while board is not None and not self._closed.is_set():
            ready = select.select([host, board], [], [], 0.1)[0]
            if host in ready:
                data = host.recv(4096)
                if not data:
                    break
                try:
                    board.sendall(data)
                except OSError:
                    pass  # the board is gone: what the host wrote is lost, and recv says so next
            if board in ready:
                try:
                    data = board.recv(4096)
                except ConnectionResetError:
                    data = b""
                if not data:  # the board went away: wait for it to listen again
                    board.close()
                    board = self._board()
                    self.reconnects += 1
                    continue
                self._watch(data)
                host.sendall(data)
        host.close()
        if board is not None:
            board.close()
