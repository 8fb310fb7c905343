"""G-code words with modal state → a Program of moves in machine coordinates.

Supported: G0 G1 G2 G3 (I/J/K and R forms, planes G17/G18/G19), G4 (P in
seconds), G20/G21, G90/G91, F (units per minute), N, M0, M2/M30; the
spindle or laser and coolant (M3/M4/M5 with S, M7/M8/M9; M2/M30 turn them
off); T and M6, a tool change: a pause for the operator with the spindle and
coolant off, then back on as they were; G61 (exact stop) and G64 (P: the
path tolerance at corners, which the cornering rule uses); work
coordinates as GRBL and LinuxCNC have them (quadstep.coordinates): G54–G59,
G10 L2/L20 Pn, G53 (machine coordinates for the line's G0/G1), G92, G92.1,
G92.2, G92.3, G28/G30 (through an optional point, then to the stored
position) and G28.1/G30.1; G43.1 Z (a tool length offset on Z, GRBL's
dynamic one) and G49; M1 (an optional stop: ignored, as GRBL has no switch
for it); G93 (inverse time: each G1/G2/G3 takes 1/F minutes, F on its own
line) and G94; and G40 G80 G91.1, which only select the one mode quadstep
has. Words on a line take effect in this order (GRBL's and LinuxCNC's):
units, feed mode, feed, S, T, M6, M3/M4/M5, M7/M8/M9, plane, tool length offset, coordinate
system, path mode, distance mode, then one of dwell, G10, G28/G30,
G28.1/G30.1, G92…, then motion, then M0/M2/M30. Arc offsets I/J/K are
always relative to the arc's start. Every move carries the work offset it
was given in, so that a move outside the travel is named by its own value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from ..coordinates import TOOL_LENGTH_AXIS, WorkCoordinates
from ..planner.program import (
    MAX_DWELL_S,
    Dwell,
    LinearMove,
    OutputState,
    Pause,
    Program,
    SetOutputs,
)
from . import offsets
from .arcs import MAX_ARC_CHORDS, chord_count, radius_center, sweep_angle
from .lines import PROBING, Line, code, sort_words, whole
from .probing import probe_move
from .words import GcodeError, Word, split_words

MM_PER_INCH = 25.4

# plane → (first axis, second axis, normal axis), and the offset letters of the first two
_PLANES = {17: ("X", "Y", "Z"), 18: ("Z", "X", "Y"), 19: ("Y", "Z", "X")}
_PLANE_OFFSETS = {17: ("I", "J"), 18: ("K", "I"), 19: ("J", "K")}
# Value words and the G codes that use them (S, T and F are used on any line).
_USERS = {"P": ("4", "10", "64"), "L": ("10",), "Q": ("64",)}
NO_FEED = "GRBL error 22: feed rate has not yet been set or is undefined"


def _first(words: dict[str, Word]) -> Word:
    return min(words.values(), key=lambda w: w.column)


class GcodeInterpreter:
    """Reads lines in order, keeping the modal state, and appends items to a Program.

    `start` is the machine position (mm); `coordinates` the work coordinates at the start, which the
    program changes as it goes (the Program's `coordinates` is where it leaves them).
    """

    def __init__(
        self,
        axis_names: Sequence[str],
        start: Sequence[float],
        arc_tolerance: float,
        skip_unsupported: bool = False,
        coordinates: WorkCoordinates | None = None,
    ) -> None:
        self.axis_names = tuple(axis_names)
        self.position = [float(x) for x in start]  # machine mm
        self.coords = (
            coordinates.model_copy(deep=True) if coordinates is not None else WorkCoordinates()
        )
        self.arc_tolerance = arc_tolerance
        self.skip_unsupported = skip_unsupported
        self.units = 1.0  # mm per program unit
        self.absolute = True
        self.plane = 17
        self.motion: int | None = 0  # G0 at the start, as GRBL and LinuxCNC begin
        self.feed: float | None = None  # mm/s
        self.inverse_time = False  # G93: a feed move takes 1/F minutes, F given on its line
        self._moves_per_minute: float | None = None  # this line's F, in G93
        # G64 P (mm), 0 after G61, None: the configuration's cornering
        self.deviation: float | None = None
        self.outputs = OutputState()
        self.tool: int | None = None  # the tool T selected
        self.program = Program(coordinates=self.coords)
        self.source: list[str] = []  # the file's lines, for reading on after a probe
        # the work offsets of the last move: the moves between two changes share one tuple (a long
        # running job keeps every move)
        self._offsets_in_force: tuple[float, ...] = ()

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
        parsed = sort_words(
            words, line, self.axis_names, self.program.skipped if self.skip_unsupported else None
        )
        self._execute(parsed, line)
        if parsed.stop is not None:
            if whole(parsed.stop) == 0:
                self.program.items.append(
                    Pause(line, coordinates=self.coords.model_copy(deep=True))
                )
            elif whole(parsed.stop) != 1:
                self._set_outputs(OutputState(speed=self.outputs.speed), line)
                self.coords.program_end()
                self.program.end_line = line
                return False
        return True

    # -- executing -----------------------------------------------------------

    def _execute(self, p: Line, line: int) -> None:
        self._set_modes(p, line)
        path = p.g.get("path mode")
        g = p.g.get("non-modal")
        key = code(g) if g is not None else None
        self._check_users(p.values, key, code(path) if path is not None else None, line)
        axes = dict(p.axes)
        tool_length = p.g.get("tool length offset")
        if tool_length is not None:
            axes = self._tool_length(tool_length, axes, p, line)
        if g is not None:
            axes = self._non_modal(g, key, axes, p.values, line)
        self._motion(p.g.get("motion"), axes, p.values, line, machine=g if key == "53" else None)

    def _set_modes(self, p: Line, line: int) -> None:
        """The line's modal words, in the order they take effect: units, feed, spindle and coolant,
        plane, coordinate system, path mode, distance."""
        units = p.g.get("units")
        if units is not None:
            self.units = MM_PER_INCH if code(units) == "20" else 1.0
        self._feed_mode(p.g.get("feed mode"))
        feed = p.values.get("F")
        if feed is not None:
            if feed.value <= 0:
                raise GcodeError(
                    line, feed.column, f"'{feed.text}': the feed rate must be greater than 0"
                )
            if self.inverse_time:
                self._moves_per_minute = feed.value
            else:
                self.feed = feed.value * self.units / 60.0
        self._spindle_words(p, line)
        plane = p.g.get("plane")
        if plane is not None:
            self.plane = int(plane.value)
        system = p.g.get("coordinate system")
        if system is not None:
            offsets.select_system(self.coords, system)
        path = p.g.get("path mode")
        if path is not None:
            self._path_mode(path, p.values.get("P"), line)
        distance = p.g.get("distance")
        if distance is not None:
            self.absolute = code(distance) == "90"

    def _feed_mode(self, mode: Word | None) -> None:
        """G93 and G94, as GRBL has them: the feed is undefined in G93 but for the line that gives
        F, and after G93 until an F sets one."""
        self._moves_per_minute = None
        inverse = self.inverse_time if mode is None else code(mode) == "93"
        if inverse or self.inverse_time != inverse:
            self.feed = None
        self.inverse_time = inverse

    def _move_feed(self, begin: Sequence[float], points: Sequence[Sequence[float]]) -> float | None:
        """A feed move's speed, mm/s: the modal feed, or in G93 its path (every axis, as the planner
        measures it) over the 1/F minutes it is given."""
        if not self.inverse_time or self._moves_per_minute is None:
            return self.feed
        length = sum(math.dist(a, b) for a, b in zip([begin, *points], points))
        return max(length, 1e-9) * self._moves_per_minute / 60.0

    def _tool_length(
        self, word: Word, axes: dict[str, Word], p: Line, line: int
    ) -> dict[str, Word]:
        """G43.1 Z…: the tool length offset on Z, from the next move on (its axis word taken:
        nothing moves); G49: none."""
        if code(word) == "49":
            self.coords.tlo = 0.0
            return axes
        others = [w for letter, w in axes.items() if letter != TOOL_LENGTH_AXIS]
        if TOOL_LENGTH_AXIS not in axes or others:
            column = others[0].column if others else word.column
            raise GcodeError(
                line, column, f"G43.1 takes one axis word, {TOOL_LENGTH_AXIS}: the tool's length"
            )
        for other in (p.g.get("motion"), p.g.get("non-modal")):
            if other is not None:
                raise GcodeError(
                    line, other.column, f"'{other.text}' and G43.1 both want the line's axis words"
                )
        self.coords.tlo = axes[TOOL_LENGTH_AXIS].value * self.units
        return {}

    def _check_users(
        self, values: dict[str, Word], key: str | None, path_key: str | None, line: int
    ) -> None:
        """A value word (P, L, …) only with a G code that reads it."""
        for letter, users in _USERS.items():
            word = values.get(letter)
            if word is not None and key not in users and path_key not in users:
                names = ["G" + u for u in users]
                listed = names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"
                raise GcodeError(line, word.column, f"'{word.text}' is only used with {listed}")

    def _non_modal(
        self,
        g: Word,
        key: str | None,
        axes: dict[str, Word],
        values: dict[str, Word],
        line: int,
    ) -> dict[str, Word]:
        """G4, G10, G28/G30, G28.1/G30.1, G92…: the axis words left for a motion."""
        if key == "4":
            self._dwell(g, values.get("P"), axes, line)
        elif key == "10":
            offsets.g10(
                self.coords, g, axes, values, line, self.position, self.axis_names, self.units
            )
            axes = {}
        elif key in ("28", "30"):
            self._return(g, int(g.value), axes, line)
            axes = {}
        elif key in ("28.1", "30.1"):
            offsets.store(self.coords, key, axes, line, self.position, self.axis_names)
        elif key is not None and key.startswith("92"):
            offsets.g92(self.coords, g, key, axes, line, self.position, self.axis_names, self.units)
            axes = {}
        return axes

    def _spindle_words(self, p: Line, line: int) -> None:
        """S, T, M6, M3/M4/M5, M7/M8/M9, in that order."""
        speed_word, tool_word = p.values.get("S"), p.values.get("T")
        if speed_word is None and tool_word is None and not p.m:
            return  # most lines: nothing to change
        speed = self.outputs.speed
        if speed_word is not None:
            if speed_word.value < 0:
                raise GcodeError(
                    line,
                    speed_word.column,
                    f"'{speed_word.text}': the spindle speed must be at least 0",
                )
            speed = speed_word.value
        if tool_word is not None:
            if tool_word.value != int(tool_word.value) or tool_word.value < 0:
                raise GcodeError(
                    line, tool_word.column, f"'{tool_word.text}': a tool is a whole number"
                )
            self.tool = int(tool_word.value)
        if "tool change" in p.m:
            self._tool_change(line)
        spindle, mist, flood = (p.m.get(k) for k in ("spindle", "mist", "flood"))
        state = replace(self.outputs, speed=speed)
        if spindle is not None:
            state = replace(state, spindle=int(spindle.value))
        if "coolant off" in p.m:
            state = replace(state, mist=False, flood=False)
        state = replace(
            state, mist=state.mist or mist is not None, flood=state.flood or flood is not None
        )
        self._set_outputs(state, line)

    def _tool_change(self, line: int) -> None:
        """M6: the spindle and coolant off, a pause for the operator, then on again as they were."""
        if self.tool is None:
            raise GcodeError(line, 1, "M6 needs a tool: no T on this line or before")
        running = self.outputs
        self._set_outputs(OutputState(speed=running.speed), line)
        self.program.items.append(
            Pause(line, tool=self.tool, coordinates=self.coords.model_copy(deep=True))
        )
        self._set_outputs(running, line)

    def _set_outputs(self, state: OutputState, line: int) -> None:
        if state != self.outputs:
            self.outputs = state
            self.program.items.append(SetOutputs(line, state))

    def _path_mode(self, path: Word, tolerance: Word | None, line: int) -> None:
        """G61 and G61.1: stop at every corner; G64: corners within P mm of the path (or the
        configuration's)."""
        if code(path) != "64":
            self.deviation = 0.0
        elif tolerance is None:
            self.deviation = None
        elif not 0 < tolerance.value * self.units <= 10:
            raise GcodeError(
                line,
                tolerance.column,
                f"'{tolerance.text}': the path tolerance must be greater than 0 and at most 10 mm",
            )
        else:
            self.deviation = tolerance.value * self.units

    def _dwell(self, g4: Word, pause: Word | None, axes: dict[str, Word], line: int) -> None:
        if pause is None:
            raise GcodeError(line, g4.column, "G4 needs P (seconds)")
        if axes:
            first = _first(axes)
            raise GcodeError(line, first.column, f"'{first.text}': G4 takes no axis words")
        if pause.value < 0:
            raise GcodeError(
                line, pause.column, f"'{pause.text}': the dwell must be at least 0 seconds"
            )
        if pause.value > MAX_DWELL_S:
            raise GcodeError(
                line,
                pause.column,
                f"'{pause.text}': a dwell may last at most "
                f"{MAX_DWELL_S:g} s (an hour; M0 waits for the operator as long as "
                "it takes)",
            )
        self.program.items.append(Dwell(line, pause.value))

    def _return(self, g: Word, which: int, axes: dict[str, Word], line: int) -> None:
        """G28/G30: rapid through the point the axis words give (if any), then to the stored
        position, of the axes named (all of them when none is)."""
        if axes:
            self._move(self._target(axes), None, line)
        names = (
            [letter for letter in self.axis_names if letter in axes]
            if axes
            else list(self.axis_names)
        )
        target = [
            self.coords.stored(which, a) if a in names else x
            for a, x in zip(self.axis_names, self.position)
        ]
        self._move(target, None, line, machine=True)

    def _target(self, axes: dict[str, Word], machine: bool = False) -> list[float]:
        """Machine mm of the axis words: work coordinates (or machine ones, for G53), absolute or
        relative."""
        target = list(self.position)
        for letter, w in axes.items():
            i = self.axis_names.index(letter)
            value = w.value * self.units
            if machine:
                target[i] = value
            elif self.absolute:
                target[i] = value + self.coords.offset(letter)
            else:
                target[i] += value
        return target

    def _offsets(self, machine: bool) -> tuple[tuple[float, ...], str]:
        offsets = (
            (0.0,) * len(self.axis_names)
            if machine
            else tuple(self.coords.offset(a) for a in self.axis_names)
        )
        if offsets != self._offsets_in_force:
            self._offsets_in_force = offsets
        return self._offsets_in_force, "G53" if machine else self.coords.name

    def _move(
        self, target: list[float], feed: float | None, line: int, machine: bool = False
    ) -> None:
        offset, system = self._offsets(machine)
        self.program.items.append(
            LinearMove(
                line, tuple(target), feed, offset=offset, system=system, deviation=self.deviation
            )
        )
        self.position = target

    def _motion(
        self,
        motion: Word | None,
        axes: dict[str, Word],
        values: dict[str, Word],
        line: int,
        machine: Word | None = None,
    ) -> None:
        # a probe: the motion mode stays as it was
        if motion is not None and code(motion) in PROBING:
            if machine is not None:
                raise GcodeError(line, machine.column, "G53 does not apply to probing")
            probe_move(self, motion, axes, line, NO_FEED)
            return
        if motion is not None:
            self.motion = int(motion.value)
        arc_words = {k: w for k, w in values.items() if k in "IJKR"}
        mode = self.motion
        is_arc = mode in (2, 3)
        if arc_words and not is_arc:
            first = _first(arc_words)
            raise GcodeError(line, first.column, f"'{first.text}' is only used with G2/G3")
        if not axes and not (is_arc and (arc_words or motion is not None)):
            return
        where = motion if motion is not None else _first(axes)
        if mode is None or mode == 80:
            raise GcodeError(
                line,
                where.column,
                f"'{where.text}': axis words without a motion mode (G0, G1, G2 or G3)",
            )
        if machine is not None and (is_arc or not self.absolute):
            why = "G0 or G1" if is_arc else "absolute distance (G90)"
            raise GcodeError(
                line, machine.column, f"G53 moves in machine coordinates only with {why}"
            )
        if mode != 0 and self.inverse_time and self._moves_per_minute is None:
            raise GcodeError(
                line,
                where.column,
                f"G{mode} in inverse time (G93) needs F on its own line ({NO_FEED})",
            )
        if mode != 0 and not self.inverse_time and self.feed is None:
            raise GcodeError(
                line,
                where.column,
                f"G{mode} needs a feed rate: no F on this line or before ({NO_FEED})",
            )
        target = self._target(axes, machine=machine is not None)
        feed = None if mode == 0 else self._move_feed(self.position, [target])
        if is_arc:
            self._arc(mode == 2, target, arc_words, where, line)
            self.position = target
        else:
            self._move(target, feed, line, machine=machine is not None)

    def _arc(
        self, clockwise: bool, target: list[float], words: dict[str, Word], where: Word, line: int
    ) -> None:
        name = f"G{2 if clockwise else 3}"
        first, second, normal = _PLANES[self.plane]
        if first not in self.axis_names or second not in self.axis_names:
            raise GcodeError(
                line,
                where.column,
                f"G{self.plane} arcs need axes {first} and {second} on this machine",
            )
        offset_letters = _PLANE_OFFSETS[self.plane]
        for w in words.values():
            if w.letter in "IJK" and w.letter not in offset_letters:
                raise GcodeError(
                    line,
                    w.column,
                    f"'{w.text}' is not an offset in the G{self.plane} plane "
                    f"({', '.join(offset_letters)})",
                )
        i1, i2 = self.axis_names.index(first), self.axis_names.index(second)
        start = (self.position[i1], self.position[i2])
        end = (target[i1], target[i2])
        radius_word = words.get("R")
        offsets = [words.get(k) for k in offset_letters]
        if radius_word is not None and any(offsets):
            raise GcodeError(
                line,
                radius_word.column,
                f"{name} takes either R or {'/'.join(offset_letters)}, not both",
            )
        if radius_word is not None:
            center = self._radius_form(radius_word, start, end, clockwise, line)
            radius = abs(radius_word.value) * self.units
        else:
            if not any(offsets):
                raise GcodeError(
                    line, where.column, f"{name} needs {'/'.join(offset_letters)} offsets or R"
                )
            di, dj = (w.value * self.units if w is not None else 0.0 for w in offsets)
            center = (start[0] + di, start[1] + dj)
            radius = math.dist(start, center)
            end_radius = math.dist(end, center)
            if abs(radius - end_radius) > 0.005 and abs(radius - end_radius) > 0.001 * radius:
                raise GcodeError(
                    line,
                    where.column,
                    f"{name} end point is not on the arc: radius {radius:.3f} mm at the start, "
                    f"{end_radius:.3f} mm at the end",
                )
        if radius == 0.0:
            raise GcodeError(line, where.column, f"{name} has radius 0")
        sweep = sweep_angle(start, end, center, clockwise)
        chords = chord_count(radius, sweep, self.arc_tolerance)
        if chords > MAX_ARC_CHORDS:
            raise GcodeError(
                line,
                where.column,
                f"{name} of radius {radius:.6g} mm would be more "
                f"than {MAX_ARC_CHORDS} chords at arc_tolerance "
                f"{self.arc_tolerance:g} mm",
            )
        angle0 = math.atan2(start[1] - center[1], start[0] - center[0])
        begin = list(self.position)
        points = []
        for k in range(1, chords):
            f = k / chords
            point = [b + (t - b) * f for b, t in zip(begin, target)]
            point[i1] = center[0] + radius * math.cos(angle0 + sweep * f)
            point[i2] = center[1] + radius * math.sin(angle0 + sweep * f)
            points.append(tuple(point))
        points.append(tuple(target))
        self._chords(points, self._move_feed(begin, points), line)

    def _chords(self, points: list[tuple[float, ...]], feed: float | None, line: int) -> None:
        """An arc's chords, at one feed."""
        offset, system = self._offsets(False)
        for point in points:
            self.program.items.append(
                LinearMove(
                    line, point, feed, offset=offset, system=system, deviation=self.deviation
                )
            )

    def _radius_form(
        self,
        radius_word: Word,
        start: tuple[float, float],
        end: tuple[float, float],
        clockwise: bool,
        line: int,
    ) -> tuple[float, float]:
        if math.dist(start, end) < 1e-9:
            raise GcodeError(
                line,
                radius_word.column,
                "an R-form arc needs an end point different from its start",
            )
        radius = radius_word.value * self.units
        center = radius_center(start, end, radius, clockwise)
        if center is None:
            raise GcodeError(
                line,
                radius_word.column,
                f"'{radius_word.text}': radius {abs(radius):.3f} mm is less than half the distance "
                f"to the end point ({math.dist(start, end) / 2:.3f} mm)",
            )
        return center


def parse_gcode(
    text: str,
    axis_names: Sequence[str],
    start: Sequence[float] | None = None,
    arc_tolerance: float = 0.002,
    skip_unsupported: bool = False,
    coordinates: WorkCoordinates | None = None,
) -> Program:
    """Parse a whole G-code text; raises GcodeError at the first problem."""
    interpreter = GcodeInterpreter(
        axis_names, start or [0.0] * len(axis_names), arc_tolerance, skip_unsupported, coordinates
    )
    # Lines end at a newline only, as an editor counts them (not at \x1c-\x1e, \x85 or \u2028).
    # A final newline ends the last line; it does not begin another.
    lines = text.removesuffix("\n").split("\n") if text else []
    interpreter.source = [line.removesuffix("\r") for line in lines]
    for number, line in enumerate(interpreter.source, start=1):
        if not interpreter.feed_line(line, number):
            rest = interpreter.source[number:]
            interpreter.program.after_end = sum(1 for text in rest if text.strip(" \t%"))
            break
    return interpreter.program
