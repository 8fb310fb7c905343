"""G-code words with modal state → a Program of moves in machine coordinates.

Supported: G0 G1 G2 G3 (I/J/K and R forms, planes G17/G18/G19), G4 (P in
seconds), G20/G21, G90/G91, G92, F (units per minute), N, M0, M2/M30, and
G40 G49 G54 G80 G94, which only select the one mode quadstep has. Words on a
line take effect in this order: units, feed, plane, distance mode, dwell,
G92, motion, then M0/M2/M30. Arc offsets I/J/K are always relative to the
arc's start.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..planner.program import Dwell, LinearMove, Pause, Program
from .arcs import chord_count, radius_center, sweep_angle
from .words import GcodeError, Word, split_words

MM_PER_INCH = 25.4

_G_GROUPS = {
    0: "motion", 1: "motion", 2: "motion", 3: "motion", 80: "motion",
    4: "non-modal", 92: "non-modal",
    17: "plane", 18: "plane", 19: "plane",
    20: "units", 21: "units",
    90: "distance", 91: "distance",
    94: "feed mode", 54: "coordinate system", 40: "cutter compensation", 49: "tool length offset",
}
_M_STOPS = {0, 2, 30}
_M_SKIPPABLE = {
    3: "spindle on", 4: "spindle on", 5: "spindle off", 6: "tool change",
    7: "coolant on", 8: "coolant on", 9: "coolant off",
}
_LETTERS_SKIPPABLE = {"S": "spindle speed", "T": "tool"}
_AXIS_LETTERS = "XYZA"
_VALUE_LETTERS = "IJKRFP"
# plane → (first axis, second axis, normal axis), and the offset letters of the first two
_PLANES = {17: ("X", "Y", "Z"), 18: ("Z", "X", "Y"), 19: ("Y", "Z", "X")}
_PLANE_OFFSETS = {17: ("I", "J"), 18: ("K", "I"), 19: ("J", "K")}
_SKIP_HINT = "--skip-unsupported skips spindle, coolant and tool words"


def _code(word: Word) -> int | None:
    """The whole-number code of a G or M word, None for codes like G38.2."""
    return int(word.value) if word.value == int(word.value) and word.value >= 0 else None


@dataclass
class _Line:
    """The words of one line, sorted by kind."""

    g: dict[str, Word]  # modal group → word
    stop: Word | None  # M0/M2/M30
    axes: dict[str, Word]
    values: dict[str, Word]  # I J K R F P


class GcodeInterpreter:
    """Reads lines in order, keeping the modal state, and appends items to a Program."""

    def __init__(
        self,
        axis_names: Sequence[str],
        start: Sequence[float],
        arc_tolerance: float,
        skip_unsupported: bool = False,
    ) -> None:
        self.axis_names = tuple(axis_names)
        self.position = [float(x) for x in start]
        self.offset = [0.0] * len(self.axis_names)
        self.arc_tolerance = arc_tolerance
        self.skip_unsupported = skip_unsupported
        self.units = 1.0  # mm per program unit
        self.absolute = True
        self.plane = 17
        self.motion: int | None = None
        self.feed: float | None = None  # mm/s
        self.program = Program()

    # -- reading -------------------------------------------------------------

    def feed_line(self, text: str, line: int) -> bool:
        """Interpret one line; False once M2/M30 ends the program."""
        self.program.lines = line
        if text.strip() == "%":
            return True
        words = split_words(text, line)
        if words and words[0].letter == "N":
            words = words[1:]
        if not words:
            return True
        parsed = self._sort(words, line)
        self._execute(parsed, line)
        if parsed.stop is not None:
            code = _code(parsed.stop)
            if code == 0:
                self.program.items.append(Pause(line))
            else:
                self.program.end_line = line
                return False
        return True

    def _unsupported(self, word: Word, line: int, what: str | None) -> bool:
        """Skip a spindle/coolant/tool word when allowed (True); otherwise raise."""
        if what is None:
            raise GcodeError(line, word.column, f"'{word.text}' is not supported")
        if not self.skip_unsupported:
            raise GcodeError(line, word.column, f"'{word.text}' ({what}) is not supported; {_SKIP_HINT}")
        self.program.skipped.append((line, word.text))
        return True

    def _sort(self, words: list[Word], line: int) -> _Line:
        parsed = _Line(g={}, stop=None, axes={}, values={})
        for w in words:
            if w.letter == "N":
                raise GcodeError(line, w.column, f"'{w.text}' (line number) must be the first word")
            if w.letter == "G":
                code = _code(w)
                group = _G_GROUPS.get(code) if code is not None else None
                if group is None:
                    self._unsupported(w, line, None)
                    continue
                if group in parsed.g:
                    first = parsed.g[group]
                    raise GcodeError(line, w.column, f"'{w.text}' and '{first.text}' are both in the {group} group")
                parsed.g[group] = w
            elif w.letter == "M":
                code = _code(w)
                if code in _M_STOPS:
                    if parsed.stop is not None:
                        raise GcodeError(line, w.column, f"'{w.text}' and '{parsed.stop.text}' are both program stops")
                    parsed.stop = w
                else:
                    self._unsupported(w, line, _M_SKIPPABLE.get(code) if code is not None else None)
            elif w.letter in _LETTERS_SKIPPABLE:
                self._unsupported(w, line, _LETTERS_SKIPPABLE[w.letter])
            elif w.letter in _AXIS_LETTERS or w.letter in _VALUE_LETTERS:
                if w.letter in _AXIS_LETTERS and w.letter not in self.axis_names:
                    raise GcodeError(
                        line, w.column,
                        f"'{w.text}': axis {w.letter} is not on this machine (axes {', '.join(self.axis_names)})",
                    )
                table = parsed.axes if w.letter in _AXIS_LETTERS else parsed.values
                if w.letter in table:
                    first = table[w.letter]
                    raise GcodeError(line, w.column, f"'{w.text}' repeats {w.letter} (first at column {first.column})")
                table[w.letter] = w
            else:
                self._unsupported(w, line, None)
        return parsed

    # -- executing -----------------------------------------------------------

    def _execute(self, p: _Line, line: int) -> None:
        units = p.g.get("units")
        if units is not None:
            self.units = MM_PER_INCH if _code(units) == 20 else 1.0
        feed = p.values.get("F")
        if feed is not None:
            if feed.value <= 0:
                raise GcodeError(line, feed.column, f"'{feed.text}': the feed rate must be greater than 0")
            self.feed = feed.value * self.units / 60.0
        plane = p.g.get("plane")
        if plane is not None:
            self.plane = _code(plane) or 17
        distance = p.g.get("distance")
        if distance is not None:
            self.absolute = _code(distance) == 90
        axes = dict(p.axes)
        non_modal = p.g.get("non-modal")
        pause = p.values.get("P")
        if non_modal is not None and _code(non_modal) == 4:
            self._dwell(non_modal, pause, axes, line)
        elif pause is not None:
            raise GcodeError(line, pause.column, f"'{pause.text}' is only used with G4")
        if non_modal is not None and _code(non_modal) == 92:
            self._set_offset(non_modal, axes, line)
            axes = {}
        self._motion(p.g.get("motion"), axes, p.values, line)

    def _dwell(self, g4: Word, pause: Word | None, axes: dict[str, Word], line: int) -> None:
        if pause is None:
            raise GcodeError(line, g4.column, "G4 needs P (seconds)")
        if axes:
            first = min(axes.values(), key=lambda w: w.column)
            raise GcodeError(line, first.column, f"'{first.text}': G4 takes no axis words")
        if pause.value < 0:
            raise GcodeError(line, pause.column, f"'{pause.text}': the dwell must be at least 0 seconds")
        self.program.items.append(Dwell(line, pause.value))

    def _set_offset(self, g92: Word, axes: dict[str, Word], line: int) -> None:
        if not axes:
            raise GcodeError(line, g92.column, "G92 needs at least one axis word")
        for letter, w in axes.items():
            i = self.axis_names.index(letter)
            self.offset[i] = self.position[i] - w.value * self.units

    def _target(self, axes: dict[str, Word]) -> list[float]:
        target = list(self.position)
        for letter, w in axes.items():
            i = self.axis_names.index(letter)
            value = w.value * self.units
            target[i] = value + self.offset[i] if self.absolute else target[i] + value
        return target

    def _motion(self, motion: Word | None, axes: dict[str, Word], values: dict[str, Word], line: int) -> None:
        if motion is not None:
            self.motion = _code(motion)
        arc_words = {k: w for k, w in values.items() if k in "IJKR"}
        mode = self.motion
        is_arc = mode in (2, 3)
        if arc_words and not is_arc:
            first = min(arc_words.values(), key=lambda w: w.column)
            raise GcodeError(line, first.column, f"'{first.text}' is only used with G2/G3")
        if not axes and not (is_arc and (arc_words or motion is not None)):
            return
        where = motion if motion is not None else min(axes.values(), key=lambda w: w.column)
        if mode is None or mode == 80:
            raise GcodeError(line, where.column, f"'{where.text}': axis words without a motion mode (G0, G1, G2 or G3)")
        if mode != 0 and self.feed is None:
            raise GcodeError(line, where.column, f"G{mode} needs a feed rate: no F on this line or before")
        target = self._target(axes)
        feed = None if mode == 0 else self.feed
        if is_arc:
            self._arc(mode == 2, target, arc_words, where, line)
        else:
            self.program.items.append(LinearMove(line, tuple(target), feed))
        self.position = target

    def _arc(self, clockwise: bool, target: list[float], words: dict[str, Word], where: Word, line: int) -> None:
        name = f"G{2 if clockwise else 3}"
        first, second, normal = _PLANES[self.plane]
        if first not in self.axis_names or second not in self.axis_names:
            raise GcodeError(line, where.column, f"G{self.plane} arcs need axes {first} and {second} on this machine")
        offset_letters = _PLANE_OFFSETS[self.plane]
        for w in words.values():
            if w.letter in "IJK" and w.letter not in offset_letters:
                raise GcodeError(
                    line, w.column,
                    f"'{w.text}' is not an offset in the G{self.plane} plane ({', '.join(offset_letters)})",
                )
        i1, i2 = self.axis_names.index(first), self.axis_names.index(second)
        start = (self.position[i1], self.position[i2])
        end = (target[i1], target[i2])
        radius_word = words.get("R")
        offsets = [words.get(k) for k in offset_letters]
        if radius_word is not None and any(offsets):
            raise GcodeError(line, radius_word.column, f"{name} takes either R or {'/'.join(offset_letters)}, not both")
        if radius_word is not None:
            center = self._radius_form(radius_word, start, end, clockwise, line)
            radius = abs(radius_word.value) * self.units
        else:
            if not any(offsets):
                raise GcodeError(line, where.column, f"{name} needs {'/'.join(offset_letters)} offsets or R")
            di, dj = (w.value * self.units if w is not None else 0.0 for w in offsets)
            center = (start[0] + di, start[1] + dj)
            radius = math.dist(start, center)
            end_radius = math.dist(end, center)
            if abs(radius - end_radius) > 0.005 and abs(radius - end_radius) > 0.001 * radius:
                raise GcodeError(
                    line, where.column,
                    f"{name} end point is not on the arc: radius {radius:.3f} mm at the start, "
                    f"{end_radius:.3f} mm at the end",
                )
        if radius == 0.0:
            raise GcodeError(line, where.column, f"{name} has radius 0")
        sweep = sweep_angle(start, end, center, clockwise)
        chords = chord_count(radius, sweep, self.arc_tolerance)
        angle0 = math.atan2(start[1] - center[1], start[0] - center[0])
        begin = list(self.position)
        for k in range(1, chords):
            f = k / chords
            point = [b + (t - b) * f for b, t in zip(begin, target)]
            point[i1] = center[0] + radius * math.cos(angle0 + sweep * f)
            point[i2] = center[1] + radius * math.sin(angle0 + sweep * f)
            self.program.items.append(LinearMove(line, tuple(point), self.feed))
        self.program.items.append(LinearMove(line, tuple(target), self.feed))

    def _radius_form(
        self, radius_word: Word, start: tuple[float, float], end: tuple[float, float], clockwise: bool, line: int
    ) -> tuple[float, float]:
        if math.dist(start, end) < 1e-9:
            raise GcodeError(line, radius_word.column, "an R-form arc needs an end point different from its start")
        radius = radius_word.value * self.units
        center = radius_center(start, end, radius, clockwise)
        if center is None:
            raise GcodeError(
                line, radius_word.column,
                f"'{radius_word.text}': radius {abs(radius):.3f} mm is less than half the distance to the end point "
                f"({math.dist(start, end) / 2:.3f} mm)",
            )
        return center


def parse_gcode(
    text: str,
    axis_names: Sequence[str],
    start: Sequence[float] | None = None,
    arc_tolerance: float = 0.002,
    skip_unsupported: bool = False,
) -> Program:
    """Parse a whole G-code text; raises GcodeError at the first problem."""
    interpreter = GcodeInterpreter(axis_names, start or [0.0] * len(axis_names), arc_tolerance, skip_unsupported)
    for number, line in enumerate(text.splitlines(), start=1):
        if not interpreter.feed_line(line, number):
            break
    return interpreter.program
