"""What can go wrong on the link; every failure derives from LinkError."""

from __future__ import annotations

from ..protocol import Alarm, ErrorReport


class LinkError(Exception):
    """The link cannot go on: port closed, firmware unanswering, wrong version."""


class LinkTimeout(LinkError):
    """The firmware did not answer after every retry."""


class BoardSilent(LinkTimeout):
    """Nothing came back from the board for too long while it owed an answer; the link is closed."""


class ProtocolVersionError(LinkError):
    """The firmware speaks a protocol version this host does not know."""


class Stopped(LinkError):
    """stop() or a hold was called while this call was waiting; what it was sending was dropped."""


class FirmwareError(LinkError):
    """The firmware refused a frame with an ERROR report."""

    def __init__(self, report: ErrorReport) -> None:
        self.report = report
        super().__init__(f"firmware refused a frame: {report.describe()}")

    @property
    def code(self) -> str:
        return self.report.code.name

    @property
    def field(self) -> str | None:
        return self.report.field.name if self.report.field is not None else None

    @property
    def axis(self) -> int | None:
        return self.report.axis


class AlarmError(LinkError):
    """The firmware raised an alarm: motion halted, the queue was flushed."""

    def __init__(self, alarm: Alarm) -> None:
        self.alarm = alarm
        super().__init__(
            f"firmware alarm {alarm.code.name} at motion tick {alarm.motion_ticks}, "
            f"positions {list(alarm.position)}; stop() clears it"
        )


__all__ = ["AlarmError", "BoardSilent", "FirmwareError", "LinkError", "LinkTimeout", "ProtocolVersionError", "Stopped"]
