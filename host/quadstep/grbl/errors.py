"""GRBL's error and alarm numbers (its interface documentation), and quadstep's errors mapped to
them: the sender shows GRBL's meaning, quadstep's own message goes with it as a [MSG:…] line."""

from __future__ import annotations

from enum import IntEnum


class GrblError(IntEnum):
    EXPECTED_LETTER = 1
    BAD_NUMBER = 2
    INVALID_STATEMENT = 3  # a $ command not recognised
    NEGATIVE_VALUE = 4
    HOMING_DISABLED = 5
    NOT_IDLE = 8
    GCODE_LOCK = 9  # in alarm (or while jogging)
    LINE_OVERFLOW = 11
    TRAVEL_EXCEEDED = 15
    INVALID_JOG = 16
    UNSUPPORTED = 20
    MODAL_GROUP = 21
    UNDEFINED_FEED = 22
    REPEATED_WORD = 25
    NO_AXIS_WORDS = 26
    INVALID_LINE_NUMBER = 27
    WRONG_AXIS = 31
    INVALID_TARGET = 33
    ARC_RADIUS = 34
    NO_ARC_OFFSET = 35
    UNUSED_WORDS = 36
    TOOL_LENGTH_AXIS = 37  # G43.1 without Z, or with another axis


class GrblAlarm(IntEnum):
    HARD_LIMIT = 1
    SOFT_LIMIT = 2
    RESET_IN_MOTION = 3
    PROBE_FAIL_INITIAL = 4
    PROBE_FAIL_CONTACT = 5
    HOMING_FAIL_RESET = 6
    HOMING_FAIL_DOOR = 7
    HOMING_FAIL_PULLOFF = 8
    HOMING_FAIL_APPROACH = 9


# What a quadstep message says → GRBL's number; the first that matches wins.
_BY_TEXT: tuple[tuple[str, GrblError], ...] = (
    ("outside the travel", GrblError.TRAVEL_EXCEEDED),
    ("feed rate", GrblError.UNDEFINED_FEED),
    ("has no number after it", GrblError.BAD_NUMBER),
    ("a number of", GrblError.BAD_NUMBER),
    ("unexpected character", GrblError.EXPECTED_LETTER),
    ("are both in the", GrblError.MODAL_GROUP),
    ("are both program stops", GrblError.MODAL_GROUP),
    ("repeats", GrblError.REPEATED_WORD),
    ("must be the first word", GrblError.INVALID_LINE_NUMBER),
    ("is only used with", GrblError.UNUSED_WORDS),
    ("takes no axis words", GrblError.UNUSED_WORDS),
    ("G43.1 takes", GrblError.TOOL_LENGTH_AXIS),
    ("offsets or R", GrblError.NO_ARC_OFFSET),
    ("not on the arc", GrblError.INVALID_TARGET),
    ("has radius 0", GrblError.ARC_RADIUS),
    ("must be at least 0", GrblError.NEGATIVE_VALUE),
    ("arcs need axes", GrblError.WRONG_AXIS),
    ("is not supported", GrblError.UNSUPPORTED),
    ("are not supported", GrblError.UNSUPPORTED),
    ("3D printer", GrblError.UNSUPPORTED),
    ("flow control", GrblError.UNSUPPORTED),
)


def error_for(message: str) -> GrblError:
    """The GRBL error that says best what `message` (a JobError's) says; an invalid target
    otherwise."""
    for text, error in _BY_TEXT:
        if text in message:
            return error
    return GrblError.INVALID_TARGET
