"""Messages that worker threads post to the machine screen (post_message is thread-safe): the only
way their outcomes reach it."""

from __future__ import annotations

from textual.message import Message

from ..jog import JogResult
from ..machine import JobProgress, JobRun, MotionEnd
from ..protocol import IdentifyReply
from ..toolpath import Toolpath
from .preview import Preview
from .session import Snapshot


class Connected(Message):
    def __init__(self, identity: IdentifyReply) -> None:
        super().__init__()
        self.identity = identity


class ConnectionLost(Message):
    """The link failed (or could not be opened): motion state unknown until reconnected."""

    def __init__(self, reason: str) -> None:
        super().__init__()
        self.reason = reason


class StatusUpdate(Message):
    def __init__(self, snapshot: Snapshot, job: JobProgress | None) -> None:
        super().__init__()
        self.snapshot = snapshot
        self.job = job


class JogDone(Message):
    def __init__(self, result: JogResult) -> None:
        super().__init__()
        self.result = result


class JobStarted(Message):
    def __init__(
        self, job: JobRun, name: str, path: Toolpath | None = None, source: list[str] | None = None
    ) -> None:
        super().__init__()
        self.job = job
        self.name = name
        self.path = path  # to draw (None: keep the one shown)
        self.source = source or []  # the job's lines


class JobDone(Message):
    def __init__(self, name: str, end: MotionEnd) -> None:
        super().__init__()
        self.name = name
        self.end = end


class Note(Message):
    """A line for the message log; `error` ones are shown in red."""

    def __init__(self, text: str, error: bool = False) -> None:
        super().__init__()
        self.text = text
        self.error = error


class PreviewReady(Message):
    """A job planned whole and drawn, to be shown until Enter runs it or Esc drops it."""

    def __init__(self, preview: Preview, lines: list[str]) -> None:
        super().__init__()
        self.preview = preview
        self.lines = lines  # what the log says of it
