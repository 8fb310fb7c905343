"""One process at a time holds a machine: an exclusive lock (flock) on a lock file beside its state
file, held while the Machine is open. The kernel releases it when the process ends, however it ends,
so a crash never leaves a machine locked. Taking it also finds, before anything connects or moves, a
state folder where the state cannot be written."""

from __future__ import annotations

import fcntl
import os
import tempfile
from pathlib import Path

from .errors import MachineError


class MachineBusy(MachineError):
    """Another process holds the machine."""


class StateLock:
    """The lock on one machine's state; release() (or the process's end) lets the next take it."""

    def __init__(self, path: Path, fd: int) -> None:
        self.path = path
        self._fd: int | None = fd

    @classmethod
    def acquire(cls, state_file: Path, label: str) -> StateLock:
        """Take the lock of the machine whose state is `state_file` (`label` names it in messages);
        raises MachineBusy when another process holds it, MachineError when its folder cannot keep
        the state."""
        path = state_file.with_name(state_file.name + ".lock")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            # not inherited by the processes started later (an emulator that outlives a crash)
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise _unwritable(path.parent, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            who = f"another quadstep (pid {holder})" if holder else "another quadstep"
            raise MachineBusy(f"{who} holds this machine ({label}); close it first") from None
        lock = cls(path, fd)
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            _check_writable(state_file)
        except OSError as exc:
            lock.release()
            raise _unwritable(path.parent, exc) from None
        except MachineError:
            lock.release()
            raise
        return lock

    def release(self) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing the only descriptor releases the lock
            self._fd = None


def _holder(fd: int) -> int | None:
    """The pid the holder wrote (None: not written yet)."""
    try:
        text = os.pread(fd, 32, 0).decode(errors="replace").strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _check_writable(state_file: Path) -> None:
    """The state is replaced by a file written beside it and renamed over it: the folder must take
    new files, and the state file, if there, must be a file."""
    if state_file.exists() and not state_file.is_file():
        raise MachineError(f"cannot keep the machine's state in {state_file}: not a file")
    fd, probe = tempfile.mkstemp(
        dir=state_file.parent, prefix=f".{state_file.name}.", suffix=".tmp"
    )
    os.close(fd)
    os.unlink(probe)


def _unwritable(folder: Path, exc: OSError) -> MachineError:
    return MachineError(
        f"cannot keep the machine's state in {folder}: {exc.strerror or exc}; "
        "make it writable or set XDG_STATE_HOME to a folder that is"
    )
