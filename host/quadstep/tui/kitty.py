"""Key releases from terminals that speak the kitty keyboard protocol (kitty, WezTerm, foot,
Ghostty).

Textual turns the protocol on without its "report event types" flag, so it never hears a key let go,
and its parser cannot read a key event that carries an event type. This driver sets that flag as
well (flags 1, 2, 8 and 16: disambiguate, event types, every key as an escape code, the text), asks
the terminal which flags it took (`CSI ? u`; a terminal without the protocol stays silent) and reads
the events itself: a press (type 1) or a repeat (type 2) goes on as Textual's key event, a release
(type 3) becomes a KeyRelease message. The repeat timeouts stay as they are, as the fallback and a
safety net.

Protocol: https://sw.kovidgoyal.net/kitty/keyboard-protocol/ (progressive enhancement, event types).
"""

from __future__ import annotations

import os
import re
import selectors
from codecs import getincrementaldecoder
from collections.abc import Iterable

from textual import events
from textual._xterm_parser import XTermParser
from textual.drivers.linux_driver import LinuxDriver
from textual.keys import Keys
from textual.message import Message

REPORT_EVENT_TYPES = 0b10
FLAGS = 0b1 | REPORT_EVENT_TYPES | 0b1000 | 0b10000
SET_FLAGS = f"\x1b[={FLAGS};1u"  # replaces the flags of the entry Textual pushed (its exit pops it)
QUERY_FLAGS = "\x1b[?u"

_FLAGS_REPLY = re.compile(r"\x1b\[\?(\d+)u")
# CSI code[:alternates] ; modifiers:event-type [; text] final
_EVENT_TYPE = re.compile(r"(\x1b\[[\d:]*;\d*):([123])((?:;[\d:]*)?[u~ABCDEFHPQRS])")


class KeyRelease(Message):
    """A key let go (the same name Textual gives the key's press)."""

    def __init__(self, key: str) -> None:
        super().__init__()
        self.key = key


class KeyboardFlags(Message):
    """The terminal's answer to the flags query: which of the protocol's flags it applies."""

    def __init__(self, flags: int) -> None:
        super().__init__()
        self.flags = flags

    @property
    def releases(self) -> bool:
        return bool(self.flags & REPORT_EVENT_TYPES)


class ReleaseParser(XTermParser):
    """Textual's parser, with key event types and the flags reply read first. Its messages join the
    parser's own tokens in the order the terminal sent them (a press before its release)."""

    def _emit(self, message: Message) -> None:
        self._tokens.append(message)

    def _sequence_to_key_events(self, sequence: str, alt: bool = False) -> Iterable[events.Key]:
        reply = _FLAGS_REPLY.fullmatch(sequence)
        if reply is not None:
            self._emit(KeyboardFlags(int(reply.group(1))))
            return [events.Key(Keys.Ignore, sequence)]  # consumed: the parser drops an ignored key
        typed = _EVENT_TYPE.fullmatch(sequence)
        if typed is None:
            return super()._sequence_to_key_events(sequence, alt)
        head, kind, tail = typed.groups()
        if head.endswith(";"):
            head += "1"  # the modifiers field left empty: none
        keys = list(super()._sequence_to_key_events(head + tail, alt))
        if kind != "3":
            return keys
        for key in keys:
            self._emit(KeyRelease(key.key))
        return [events.Key(Keys.Ignore, sequence)]


class ReleaseDriver(LinuxDriver):
    """Textual's Linux driver with the protocol's event types on and read by ReleaseParser."""

    def start_application_mode(self) -> None:
        super().start_application_mode()
        self.write(SET_FLAGS + QUERY_FLAGS)
        self.flush()

    def run_input_thread(self) -> None:
        parser = ReleaseParser()
        decode = getincrementaldecoder("utf-8")().decode
        with selectors.SelectSelector() as selector:
            selector.register(self.fileno, selectors.EVENT_READ)
            while not self.exit_event.is_set():
                for _ in selector.select(0.1):
                    data = decode(os.read(self.fileno, 4096))
                    for message in parser.feed(data):
                        self.process_message(message)
                for message in parser.tick():
                    self.process_message(message)
