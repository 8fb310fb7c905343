"""One G-code line's words sorted by kind: a word per modal group, the program stop, axes, values.

Two words of one group on a line, a repeated letter, an axis the machine
lacks or a word quadstep does not know is an error naming the line and the
column; spindle, coolant and tool words can be skipped instead (a dry run).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NoReturn

from ..protocol.constants import AXIS_NAMES
from .words import PRINTER_FILE, GcodeError, Word

# G codes by their number as written without leading zeros ("1", "92.1"), and their modal group.
G_GROUPS = {
    "0": "motion",
    "1": "motion",
    "2": "motion",
    "3": "motion",
    "80": "motion",
    "4": "non-modal",
    "10": "non-modal",
    "28": "non-modal",
    "28.1": "non-modal",
    "30": "non-modal",
    "30.1": "non-modal",
    "53": "non-modal",
    "92": "non-modal",
    "92.1": "non-modal",
    "92.2": "non-modal",
    "92.3": "non-modal",
    "17": "plane",
    "18": "plane",
    "19": "plane",
    "20": "units",
    "21": "units",
    "90": "distance",
    "91": "distance",
    "54": "coordinate system",
    "55": "coordinate system",
    "56": "coordinate system",
    "57": "coordinate system",
    "58": "coordinate system",
    "59": "coordinate system",
    "93": "feed mode",
    "94": "feed mode",
    "40": "cutter compensation",
    "43.1": "tool length offset",
    "49": "tool length offset",
    "61": "path mode",
    "61.1": "path mode",
    "64": "path mode",
    "91.1": "arc distance",
    "38.2": "motion",
    "38.3": "motion",
    "38.4": "motion",
    "38.5": "motion",
}
CANNED_CYCLES = {"73", "81", "82", "83", "84", "85", "86", "87", "88", "89"}
PROBING = {"38.2", "38.3", "38.4", "38.5"}
M_STOPS = {0, 1, 2, 30}  # M1: an optional stop, which GRBL ignores (it has no switch for it)
M_GROUPS = {
    3: "spindle",
    4: "spindle",
    5: "spindle",
    6: "tool change",
    7: "mist",
    8: "flood",
    9: "coolant off",
}
_CLASHES = {"coolant off": ("mist", "flood"), "mist": ("coolant off",), "flood": ("coolant off",)}
M_PRINTER = {82, 83, 84, 104, 106, 107, 109, 140, 190}  # extruder modes, heaters, fans, motors off
AXIS_LETTERS = "".join(AXIS_NAMES)
VALUE_LETTERS = "IJKRFPLQST"
SKIPPABLE_LETTERS = "ST"


def code(word: Word) -> str | None:
    """A G or M word's number as a key: "1" for G1 and G01, "92.1" for G92.1; None if negative."""
    return f"{word.value:g}" if word.value >= 0 else None


def whole(word: Word) -> int | None:
    """The whole-number code of an M word, None for codes like M1.5."""
    return int(word.value) if word.value == int(word.value) and word.value >= 0 else None


@dataclass
class Line:
    """The words of one line, sorted by kind."""

    g: dict[str, Word]  # modal group → word
    stop: Word | None  # M0/M2/M30
    axes: dict[str, Word]
    values: dict[str, Word]  # I J K R F P L Q S T
    m: dict[str, Word]  # M-word group (spindle, tool change, mist, flood, coolant off) → word


def sort_words(
    words: list[Word], line: int, axis_names: Sequence[str], skip: list[tuple[int, str]] | None
) -> Line:
    """The words of `line` by kind; `skip`, when given, collects the spindle, coolant and tool words
    instead (a dry run without them)."""
    parsed = Line(g={}, stop=None, axes={}, values={}, m={})
    for w in words:
        if skip is not None and (
            (w.letter == "M" and whole(w) in M_GROUPS) or w.letter in SKIPPABLE_LETTERS
        ):
            skip.append((line, w.text))
            continue
        if w.letter == "N":
            raise GcodeError(line, w.column, f"'{w.text}' (line number) must be the first word")
        if w.letter == "G":
            _sort_g_word(parsed, w, line)
        elif w.letter == "M":
            _sort_m_word(parsed, w, line)
        elif w.letter in AXIS_LETTERS or w.letter in VALUE_LETTERS:
            _sort_value_word(parsed, w, line, axis_names)
        else:
            _unsupported(w, line)
    return parsed


def _unsupported(w: Word, line: int) -> NoReturn:
    raise GcodeError(line, w.column, f"'{w.text}' is not supported")


def _sort_g_word(parsed: Line, w: Word, line: int) -> None:
    key = code(w)
    group = G_GROUPS.get(key) if key is not None else None
    if key in CANNED_CYCLES:
        raise GcodeError(
            line,
            w.column,
            f"'{w.text}': canned cycles (G73, G81 … G89) are not supported; "
            "a CAM post for GRBL writes them as G0/G1 moves",
        )
    if key == "90.1":
        raise GcodeError(
            line,
            w.column,
            "'G90.1': absolute arc centers are not supported (I, J and K are "
            "relative to the arc's start, G91.1)",
        )
    if group is None:
        _unsupported(w, line)
    if group in parsed.g:
        first = parsed.g[group]
        raise GcodeError(
            line, w.column, f"'{w.text}' and '{first.text}' are both in the {group} group"
        )
    parsed.g[group] = w


def _sort_m_word(parsed: Line, w: Word, line: int) -> None:
    number = whole(w)
    if number in M_STOPS:
        if parsed.stop is not None:
            raise GcodeError(
                line,
                w.column,
                f"'{w.text}' and '{parsed.stop.text}' are both program stops",
            )
        parsed.stop = w
    elif number in M_GROUPS:
        group = M_GROUPS[number]
        clash = [parsed.m[g] for g in (group, *_CLASHES.get(group, ())) if g in parsed.m]
        if clash:
            raise GcodeError(
                line, w.column, f"'{w.text}' and '{clash[0].text}' contradict each other"
            )
        parsed.m[group] = w
    elif number in M_PRINTER:
        raise GcodeError(
            line, w.column, f"'{w.text}' is a 3D printer's code: this is {PRINTER_FILE}"
        )
    else:
        _unsupported(w, line)


def _sort_value_word(parsed: Line, w: Word, line: int, axis_names: Sequence[str]) -> None:
    if w.letter in AXIS_LETTERS and w.letter not in axis_names:
        raise GcodeError(
            line,
            w.column,
            f"'{w.text}': axis {w.letter} is not on this machine (axes {', '.join(axis_names)})",
        )
    table = parsed.axes if w.letter in AXIS_LETTERS else parsed.values
    if w.letter in table:
        first = table[w.letter]
        raise GcodeError(
            line,
            w.column,
            f"'{w.text}' repeats {w.letter} (first at column {first.column})",
        )
    table[w.letter] = w
