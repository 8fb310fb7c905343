"""A small, exact G-code reader: words, modal state, arcs as chords."""

from .interpreter import GcodeInterpreter, parse_gcode
from .words import GcodeError, Word, split_words

__all__ = ["GcodeError", "GcodeInterpreter", "Word", "parse_gcode", "split_words"]
