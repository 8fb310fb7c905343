"""Splitting one G-code line into words (letter + number), dropping comments.

Exact and strict: every character is either part of a word, white space, or
a comment; anything else is an error naming the line and column. Spaces may
stand between a letter and its number (`Z 20`, `G 1`), as GRBL and LinuxCNC
allow. What other dialects write — O-word flow control, `#` parameters, a 3D
printer's extruder (E) — is named as such.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..planner.program import JobError

_NUMBER = re.compile(r"[ \t]*([+-]?(?:\d+(?:\.\d*)?|\.\d+))")
PRINTER_FILE = "a 3D-printer file (extruder and heater codes); quadstep runs CNC G-code"


class GcodeError(JobError):
    """A G-code problem at a line and column."""

    def __init__(self, line: int, column: int, message: str) -> None:
        super().__init__(f"line {line}, column {column}: {message}")
        self.line = line
        self.column = column


@dataclass(frozen=True, slots=True)
class Word:
    letter: str  # upper case
    number: str  # as written
    value: float
    column: int  # 1-based column of the letter

    @property
    def text(self) -> str:
        return f"{self.letter}{self.number}"


def _is_o_word(text: str, at: int) -> bool:
    """An O-word's number or its name in angle brackets (`o100 sub`, `o<probe> sub`)."""
    return text.startswith("<", at) or _NUMBER.match(text, at) is not None


def split_words(text: str, line: int) -> list[Word]:
    """The words of one line; `(…)` and `;…` comments are dropped."""
    words: list[Word] = []
    i = 0
    end = len(text)
    while i < end:
        c = text[i]
        if c in " \t\r\n":
            i += 1
        elif c == ";":
            break
        elif c == "(":
            close = text.find(")", i + 1)
            if close < 0:
                raise GcodeError(line, i + 1, "comment '(' is not closed on this line")
            i = close + 1
        elif c in "oO" and all(w.letter == "N" for w in words) and _is_o_word(text, i + 1):
            raise GcodeError(
                line,
                i + 1,
                f"'{text[i:].split()[0][:20]}': O-word flow control (subroutines, "
                "loops, conditions) is not supported",
            )
        elif c == "#":
            raise GcodeError(line, i + 1, "'#': parameters (variables) are not supported")
        elif c.isascii() and c.isalpha():
            match = _NUMBER.match(text, i + 1)
            if c in "eE" and match is not None:
                raise GcodeError(
                    line, i + 1, f"'{c}{match.group(1)}' drives an extruder: this is {PRINTER_FILE}"
                )
            if match is None:
                raise GcodeError(line, i + 1, f"'{c}' has no number after it")
            number = match.group(1)
            value = float(number)
            if not math.isfinite(value):  # hundreds of digits
                raise GcodeError(
                    line,
                    i + 1,
                    f"'{c}{number[:12]}…': a number of {len(number)} "
                    "digits is too large to be represented",
                )
            words.append(Word(c.upper(), number, value, i + 1))
            i = match.end()
        else:
            raise GcodeError(line, i + 1, f"unexpected character {c!r}")
    return words
