"""Work done while a board is fed gives way to the link's threads.

Python runs one thread at a time. The threads that keep a board fed — the link's reader and writer
and the motion streaming segments — each need it for a moment, and often: a board's queue may hold
only ten milliseconds of short moves. A thread doing bulk work meanwhile (reading a sender's lines,
planning onto the running job) holds it for five milliseconds before the interpreter hands it on,
to whichever thread the system wakes, so that the reader can wait through several such turns while
the board runs dry. That work calls give_way() between its steps: a sleep of no time lets a waiting
thread take the interpreter at once (a yield of the processor does not: the yielding thread takes
the interpreter back first). A sleep lasts the system's timer slack, about 50 µs, so give_way() is
for work the board waits on, not for planning a whole file.
"""

from __future__ import annotations

import time

# Moves planned between two give_way()s: about 0.2 ms of planning.
GIVE_WAY_MOVES = 4


def give_way() -> None:
    """Let a thread that waits to run, run now."""
    time.sleep(0)
