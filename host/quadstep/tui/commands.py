"""Where the machine screen's work runs, off the event loop: a thread of its own for what runs long
or must never wait, the session's queue for motion commands (in the order keys were pressed).
Whatever fails becomes a red line in the log (a Note), never a crash."""

from __future__ import annotations

import threading
from collections.abc import Callable

from textual.message import Message

from ..link import LinkError, Stopped
from ..machine import MachineError
from ..planner.program import JobError
from .messages import Note
from .session import Session

Post = Callable[[Message], object]  # the screen's post_message: thread-safe


class Commands:
    def __init__(self, session: Session, post: Post) -> None:
        self.session = session
        self.post = post

    def thread(self, target: Callable[[], object], name: str) -> threading.Thread:
        """A thread of its own for what runs long (polling, a job) or must never wait (a stop):
        Textual's thread workers share the event loop's default executor, a handful of threads,
        where a HOLD could queue behind a job. Short work uses run_worker (the job preview)."""
        thread = threading.Thread(target=target, name=name, daemon=True)
        thread.start()
        return thread

    def submit(self, command: Callable[[], object], what: str) -> None:
        """`command` after every command submitted before it (the session's queue), guarded."""
        self.session.submit(lambda: self.guarded(command, what))

    def guarded(self, command: Callable[[], object], what: str) -> None:
        """Run `command` here (a worker thread); its failure becomes a red line."""
        try:
            command()
        except Stopped:  # a stop key's HOLD ended what this waited for
            self.post(Note(f"{what}: stopped: brought to rest with HOLD", error=True))
        except (LinkError, MachineError, ValueError, JobError) as exc:
            self.post(Note(f"{what}: {exc}", error=True))

    def routine(self, what: str, body: Callable[[], str]) -> None:
        """A homing or probing routine, here (a worker thread): its outcome to the log, then the
        jogger plans from where it left the machine."""
        try:
            self.post(Note(body()))
        except Stopped:  # Esc: the HOLD ended the move under way
            self.post(Note(f"{what}: stopped (Esc): brought to rest with HOLD", True))
        except (LinkError, MachineError, JobError) as exc:
            self.post(Note(f"{what}: {exc}", error=True))
        self.sync_jogger()

    def sync_jogger(self) -> None:
        """After a routine, a job or a touch-off: the jogger plans from where the machine stands."""
        jogger = self.session.jogger
        if jogger is not None and self.session.connected:
            self.submit(jogger.sync, "sync")
