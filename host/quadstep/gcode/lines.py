"""One G-code line's words sorted by kind: a word per modal group, the program stop, axes, values.

Two words of one group on a line, a repeated letter, an axis the machine
lacks or a word quadstep does not know is an error naming the line and the
column; spindle, coolant and tool words can be skipped instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..protocol.constants import AXIS_NAMES
from .words import GcodeError, Word

# G codes by their number as written without leading zeros ("1", "92.1"), and their modal group.
G_GROUPS = {
    "0": "motion", "1": "motion", "2": "motion", "3": "motion", "80": "motion",
    "4": "non-modal", "10": "non-modal", "28": "non-modal", "28.1": "non-modal", "30": "non-modal",
    "30.1": "non-modal", "53": "non-modal", "92": "non-modal", "92.1": "non-modal", "92.2": "non-modal",
    "92.3": "non-modal",
    "17": "plane", "18": "plane", "19": "plane",
    "20": "units", "21": "units",
    "90": "distance", "91": "distance",
    "54": "coordinate system", "55": "coordinate system", "56": "coordinate system", "57": "coordinate system",
    "58": "coordinate system", "59": "coordinate system",
    "94": "feed mode", "40": "cutter compensation", "49": "tool length offset",
}
M_STOPS = {0, 2, 30}
M_SKIPPABLE = {
    3: "spindle on", 4: "spindle on", 5: "spindle off", 6: "tool change",
    7: "coolant on", 8: "coolant on", 9: "coolant off",
}
LETTERS_SKIPPABLE = {"S": "spindle speed", "T": "tool"}
AXIS_LETTERS = "".join(AXIS_NAMES)
VALUE_LETTERS = "IJKRFPL"
SKIP_HINT = "--skip-unsupported skips spindle, coolant and tool words"


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
    values: dict[str, Word]  # I J K R F P L


def sort_words(words: list[Word], line: int, axis_names: Sequence[str], skip: list[tuple[int, str]] | None) -> Line:
    """The words of `line` by kind; `skip` collects the spindle, coolant and tool words skipped (None:
    they are errors)."""

    def unsupported(w: Word, what: str | None) -> None:
        if what is None:
            raise GcodeError(line, w.column, f"'{w.text}' is not supported")
        if skip is None:
            raise GcodeError(line, w.column, f"'{w.text}' ({what}) is not supported; {SKIP_HINT}")
        skip.append((line, w.text))

    parsed = Line(g={}, stop=None, axes={}, values={})
    for w in words:
        if w.letter == "N":
            raise GcodeError(line, w.column, f"'{w.text}' (line number) must be the first word")
        if w.letter == "G":
            key = code(w)
            group = G_GROUPS.get(key) if key is not None else None
            if group is None:
                unsupported(w, None)
                continue
            if group in parsed.g:
                first = parsed.g[group]
                raise GcodeError(line, w.column, f"'{w.text}' and '{first.text}' are both in the {group} group")
            parsed.g[group] = w
        elif w.letter == "M":
            number = whole(w)
            if number in M_STOPS:
                if parsed.stop is not None:
                    raise GcodeError(line, w.column, f"'{w.text}' and '{parsed.stop.text}' are both program stops")
                parsed.stop = w
            else:
                unsupported(w, M_SKIPPABLE.get(number) if number is not None else None)
        elif w.letter in LETTERS_SKIPPABLE:
            unsupported(w, LETTERS_SKIPPABLE[w.letter])
        elif w.letter in AXIS_LETTERS or w.letter in VALUE_LETTERS:
            if w.letter in AXIS_LETTERS and w.letter not in axis_names:
                raise GcodeError(
                    line, w.column,
                    f"'{w.text}': axis {w.letter} is not on this machine (axes {', '.join(axis_names)})",
                )
            table = parsed.axes if w.letter in AXIS_LETTERS else parsed.values
            if w.letter in table:
                first = table[w.letter]
                raise GcodeError(line, w.column, f"'{w.text}' repeats {w.letter} (first at column {first.column})")
            table[w.letter] = w
        else:
            unsupported(w, None)
    return parsed
