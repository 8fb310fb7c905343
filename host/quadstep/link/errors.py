"""What can go wrong on the link; every failure derives from LinkError."""

from __future__ import annotations

from ..protocol import Alarm, ErrorReport, State, StatusReport

HEARD_BYTES = 512  # bytes kept from before the board identified itself, to name another firmware


class LinkError(Exception):
    """The link cannot go on: port closed, firmware unanswering, wrong version."""

    @staticmethod
    def at_connect(heard: bytes, error: BaseException) -> BaseException:
        """Why connecting failed: a board that answered in another firmware's text (GRBL's banner,
        its `ok`s) is named, with the fix; otherwise `error` as it was."""
        if not isinstance(error, LinkError):
            return error
        if b"Grbl" in heard or b"grbl" in heard or b"ok\r\n" in heard or b"error:" in heard:
            return LinkError(
                "this board runs GRBL, not quadstep firmware: flash it with `quadstep flash`"
            )
        if b"Marlin" in heard or b"Klipper" in heard:
            return LinkError(
                "this board runs 3D-printer firmware, not quadstep firmware: flash it with "
                "`quadstep flash`"
            )
        return error


class LinkTimeout(LinkError):
    """The firmware did not answer after every retry."""


class BoardSilent(LinkTimeout):
    """Nothing came back from the board for too long while it owed an answer; the link is closed."""


class BoardReset(LinkError):
    """The board started afresh (reset button, power, a USB re-enumeration): its queue, its alarm
    and its step counts are gone; the host cannot know where the machine stands."""

    def __init__(self, done_before: int, before: StatusReport, after: StatusReport) -> None:
        self.before, self.after = before, after
        super().__init__(
            f"the board was reset: segments done went back from {done_before} to "
            f"{after.segments_done}, motion ticks from {before.motion_ticks} to "
            f"{after.motion_ticks}; what was queued is lost and it counts from "
            f"{list(after.position)} now (last position known before: {list(before.position)} "
            "steps); home the machine or set its position before going on"
        )


def status_alarm(status: StatusReport) -> AlarmError | None:
    """The alarm a status shows (its report may have been lost): the board halted, its queue
    flushed."""
    if status.state != State.ALARM or status.alarm is None:
        return None
    return AlarmError(
        Alarm(code=status.alarm, motion_ticks=status.motion_ticks, position=status.position)
    )


def known_text(status: StatusReport | None, alarm: Alarm | None) -> str:
    """What the host last knew of the board, for an error about a board that stopped answering."""
    parts = []
    if status is not None:
        parts.append(
            f"last known state {status.state.name}, position {list(status.position)} steps, "
            f"{status.segments_done} segments done"
        )
    if alarm is not None:
        parts.append(f"last alarm {alarm.code.name} at positions {list(alarm.position)}")
    return f" ({'; '.join(parts)})" if parts else ""


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
        lost = alarm.code.name in ("HARD_LIMIT", "E_STOP")
        hint = (
            "machine zero is lost: home the machine (quadstep home, or h in the TUI)"
            if lost
            else "a STOP clears it (Ctrl+X in the TUI)"
        )
        if alarm.code.name == "HOST_LOST":
            hint = (
                "this computer sent nothing for longer than the configuration's host_timeout "
                "while the machine moved (frozen, asleep or too busy), so the board braked to "
                f"rest and kept its position; {hint}"
            )
        super().__init__(
            f"firmware alarm {alarm.code.name} at motion tick {alarm.motion_ticks}, "
            f"positions {list(alarm.position)}; {hint}"
        )


__all__ = [
    "AlarmError",
    "BoardReset",
    "BoardSilent",
    "FirmwareError",
    "LinkError",
    "LinkTimeout",
    "ProtocolVersionError",
    "Stopped",
    "known_text",
    "status_alarm",
]
