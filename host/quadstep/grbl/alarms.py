"""quadstep's alarms as GRBL's ALARM:N: the firmware's (a hard limit, the abort button, a lost
host, a refused segment), homing's failures, and a batch that could not be planned; the sender shows
GRBL's meaning, quadstep's own message goes with it as [MSG:…]."""

from __future__ import annotations

from ..protocol import AlarmCode
from .errors import GrblAlarm

FIRMWARE: dict[AlarmCode, GrblAlarm] = {
    AlarmCode.HARD_LIMIT: GrblAlarm.HARD_LIMIT,
    # the abort button is GRBL's reset pin; the board stopped (position kept) or was cut off
    AlarmCode.E_STOP: GrblAlarm.RESET_IN_MOTION,
    AlarmCode.HOST_LOST: GrblAlarm.RESET_IN_MOTION,
    AlarmCode.UNDERRUN: GrblAlarm.RESET_IN_MOTION,
    AlarmCode.REJECTED_SEGMENT: GrblAlarm.RESET_IN_MOTION,
}

# What a homing failure's message says → GRBL's number; the first that matches wins.
_HOMING: tuple[tuple[str, GrblAlarm], ...] = (
    ("did not open", GrblAlarm.HOMING_FAIL_PULLOFF),
    ("no switch", GrblAlarm.HOMING_FAIL_APPROACH),
    ("stopped", GrblAlarm.HOMING_FAIL_RESET),
    ("hold", GrblAlarm.HOMING_FAIL_RESET),
)


def firmware_alarm(message: str) -> GrblAlarm | None:
    """The GRBL alarm of a firmware alarm named in `message` (an AlarmError's), if one is."""
    for code, alarm in FIRMWARE.items():
        if f"firmware alarm {code.name}" in message:
            return alarm
    return None


def fault_alarm(message: str) -> GrblAlarm:
    """A batch that could not be planned or run: the firmware's alarm if it raised one, else GRBL's
    soft limit (a limit of the whole plan)."""
    return firmware_alarm(message) or GrblAlarm.SOFT_LIMIT


def homing_alarm(message: str) -> GrblAlarm:
    """A homing cycle that failed: the switch not found (9), not let go (8), stopped (6)."""
    found = firmware_alarm(message)
    if found is not None:
        return found
    lowered = message.lower()
    for text, alarm in _HOMING:
        if text in lowered:
            return alarm
    return GrblAlarm.HOMING_FAIL_APPROACH
