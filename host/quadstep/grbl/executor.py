"""What the sender's lines ask for, planned and run on the machine in the order they came.

Lines are answered `ok` as they are queued here (at most QUEUE_LINES wait while a job runs, so a
sender's buffer fills and it waits, as with GRBL's planner buffer). A job starts with the lines
received so far once they hold more motion than a running job keeps back from the board
(queued_motion.py) or AHEAD_ITEMS of them wait, when the sender has been quiet for QUIET_S, or when
a command needs the machine at rest ($H, $C, $X). It is an open job (machine/open_end.py): the
lines that come while it runs are added to it and planned onto what the board has not been sent,
with look-ahead across them, so the machine goes on without a stop; only the end of what was
received is kept back. When the sender goes quiet, a command needs the machine at rest or a jog
comes, the job is closed and comes to rest at its end. Jogs (`$J=`) run as jobs of their own, open
the same way: the jogs a pendant or a joystick streams, a short one after another (GRBL's jogging
documentation), are planned together and run without a stop between them, until a jog cancel.

Laser rasters (raster_watch.py) run as jobs of their own, planned whole as RASTER lines: the lines
of a raster row are gathered (the queue takes up to AHEAD_ITEMS of them while a job runs) until
the row ends, the sender goes quiet or the queue is full, and a running job takes none of them:
it is closed, and the rows start once it has come to rest."""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from ..coordinates import WorkCoordinates
from ..link import LinkError
from ..machine import JobRun, JobState, Machine, MachineError
from ..machine.open_end import FLOOR_S
from ..planner.feed_override import Overrides, apply_overrides
from ..planner.plan import plan_program
from ..planner.program import Item, JobError, Program
from ..protocol import Capability
from .queued_motion import QueuedMotion
from .raster_watch import RasterWatch

QUEUE_LINES = 64  # lines accepted ahead of the machine while a job runs (AHEAD_ITEMS before)
QUIET_S = 0.05  # a sender quiet this long: what it sent is run
# a running job is closed after this long without a line (its end goes to the board anyway as the
# board runs out of what comes before it: closing sends it at once)
STREAM_QUIET_S = 0.5
AHEAD_S = 2.5  # planned motion the board has not run, beyond which a running job takes no lines
# nor with this many segments the board has not run, or this many items added and not yet planned.
# Short lines need room here: the end of a running job is kept back from the board (about 0.4 s
# on the router), and with less than that planned ahead the board is sent only a trickle that a
# small queue of 1 ms segments runs through (an Uno: 14 segments)
AHEAD_SEGMENTS = 4000
AHEAD_ITEMS = 1000
# lines are added to a running job this many at a time (each addition plans its unsent tail again),
# fewer once the sender has been quiet for QUIET_S or the job runs short
ADD_LINES = QUEUE_LINES // 2
POLL_S = 0.01  # s between looks at how far a running job is ahead, while lines wait
# A stream of jogs keeps its end back until the board holds less than this before it (a job of
# lines: open_end.FLOOR_S), so that a pendant's next jog, sent as the last one runs, is planned
# onto it rather than after a stop. A host held up longer lets the board run dry: an underrun's
# stop, exact, and the jogs go on from rest.
JOG_FLOOR_S = 0.04
# Jogs start once the sender has been quiet this long, so that jogs sent together (a joystick's,
# by character counting) start as one plan rather than the first alone, sent whole with its stop.
JOG_QUIET_S = 0.01
# Jogs waiting, and motion of jogs planned ahead of the board, at most: so that a joystick streaming
# short jogs by character counting is paced as GRBL's 15 planner blocks pace it, and the carriage
# follows a change of direction within a fraction of a second.
JOG_LINES = 15
JOG_AHEAD_S = 0.25


@dataclass
class Work:
    items: list[Item]
    coordinates: WorkCoordinates  # after its line
    line: int
    jog: bool = False


@dataclass
class Running:
    run: JobRun
    jog: bool
    hold_asked: bool = field(default=False)


class Executor:
    """One thread that takes the queued work and runs it on `machine`; `on_fault` gets the message
    of a batch that could not be planned or run (the session raises an alarm)."""

    def __init__(self, machine: Machine, on_fault: Callable[[str], None]) -> None:
        self.machine = machine
        self.on_fault = on_fault
        self._cond = threading.Condition()
        self._queue: deque[Work] = deque()
        self._running: Running | None = None
        self._taking = False  # a batch taken from the queue, not yet running
        self._taking_jog = False  # and it is jogs
        self._jog_cancels = 0  # jog cancels so far: jogs taken before one are dropped
        self._taken_after = 0  # the jog cancels before the batch taken
        self._held = False  # a feed hold with nothing moving: the queue waits for cycle start
        self._flush = 0  # callers waiting for the machine at rest: run what is queued now
        self._last = time.monotonic()
        self._motion = QueuedMotion(machine.config)  # of the lines queued before a job starts
        identity = machine.identity
        takes_rasters = identity is not None and bool(identity.capabilities & Capability.RASTER)
        self._rasters = RasterWatch(machine.config, takes_rasters)  # of the lines queued
        self._batch_rasters = False  # the batch taken holds a raster run
        self.feed_override = 100  # %, for the batches planned next (overrides.py)
        self.generation = 0  # a soft reset makes a new one; work of an older one is dropped
        self._closed = False
        self._thread = threading.Thread(target=self._loop, name="grbl-executor", daemon=True)
        self._thread.start()

    # --- from the session's line worker -------------------------------------------------------

    def submit(self, work: Work, generation: int) -> bool:
        """Queue `work` (waiting for room); False when a reset came first (the work is dropped)."""
        with self._cond:
            self._cond.wait_for(lambda: len(self._queue) < self._room() or self._stale(generation))
            if self._stale(generation):
                return False
            self._queue.append(work)
            self._motion.add(work.items)
            self._rasters.add(work.items)
            self._last = time.monotonic()
            self._cond.notify_all()
            return True

    def wait_idle(self, generation: int) -> bool:
        """Run what is queued and wait for the machine at rest; False when a reset came first."""
        with self._cond:
            self._flush += 1
            self._cond.notify_all()
            try:
                self._cond.wait_for(lambda: self._idle() or self._stale(generation))
            finally:
                self._flush -= 1
            return not self._stale(generation)

    # --- state -----------------------------------------------------------------------------

    @property
    def idle(self) -> bool:
        with self._cond:
            return self._idle()

    @property
    def jogging(self) -> bool:
        """Jogs run, or are about to (queued, taken, being planned): a sender's next `$J=` joins
        them."""
        with self._cond:
            return self._jogs_ahead()

    def _jogs_ahead(self) -> bool:
        if self._running is not None:
            return self._running.jog
        if self._taking:
            return self._taking_jog
        return bool(self._queue) and self._queue[0].jog

    def lines_waiting(self) -> int:
        """The lines queued and not yet taken into a job."""
        with self._cond:
            return len(self._queue)

    def grbl_state(self) -> str | None:
        """Run, Jog, Hold:0 (at rest, held) or Hold:1 (coming to rest); None when idle."""
        with self._cond:
            running, queued, held = self._running, bool(self._queue) or self._taking, self._held
            jogs = self._jogs_ahead()
        if running is None:
            return ("Jog" if jogs else "Hold:0" if held else "Run") if queued else None
        state = running.run.state
        if state in (JobState.HELD, JobState.PAUSED):
            return "Hold:0"
        if running.hold_asked:
            return "Hold:1"
        return "Jog" if running.jog else "Run"

    def running_job(self) -> JobRun | None:
        """The batch running now (not a jog), for the feed override."""
        running = self.running()
        return running.run if running is not None and not running.jog else None

    def running(self) -> Running | None:
        """What runs now: a batch of lines or of jogs."""
        with self._cond:
            return self._running

    # --- realtime commands ----------------------------------------------------------------

    def feed_hold(self) -> None:
        """`!`: the job comes to rest and waits for `~`; a jog is cancelled (as GRBL does)."""
        with self._cond:
            running, jogs = self._running, self._jogs_ahead()
            if running is None and not jogs:
                self._held = bool(self._queue) or self._taking
                return
            if running is not None:
                running.hold_asked = True
        if jogs:
            self.cancel_jog()
        elif running is not None:
            running.run.feed_hold()

    def cycle_start(self) -> None:
        """`~`: go on after a feed hold or an M0."""
        with self._cond:
            running, self._held = self._running, False
            if running is not None:
                running.hold_asked = False
            self._cond.notify_all()
        if running is not None and not running.jog:
            running.run.resume()

    def cancel_jog(self) -> bool:
        """0x85: the jog under way comes to rest, the queued jogs are dropped; True if one was
        stopped."""
        with self._cond:
            running = self._running
            self._jog_cancels += 1
            if any(w.jog for w in self._queue):
                self._queue = deque(w for w in self._queue if not w.jog)
                self._cond.notify_all()
        if running is None or not running.jog:
            return False
        end = running.run.halt("jog cancel")
        return end.ended_by != "done"

    def reset(self) -> bool:
        """A soft reset: the queue dropped, what moves brought to rest; True if it stopped
        motion."""
        with self._cond:
            self.generation += 1
            self._queue.clear()
            self._motion.clear()
            self._rasters.clear()
            self._held = False
            running = self._running
            self._cond.notify_all()
        if running is None:
            return False
        end = running.run.halt("reset")
        return end.ended_by != "done"

    def close(self) -> None:
        self.reset()
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        self._thread.join(timeout=10)

    # --- the thread ------------------------------------------------------------------------

    def _stale(self, generation: int) -> bool:
        return generation != self.generation or self._closed

    def _idle(self) -> bool:
        return not self._queue and self._running is None and not self._taking

    def _room(self) -> int:
        """Under the lock: the lines the queue takes, fewer while a job runs (they go to it) or
        jogs wait."""
        if self._jogs_ahead():
            return JOG_LINES
        running = self._running is not None or self._taking
        return QUEUE_LINES if running and not self._rasters.holds_run else AHEAD_ITEMS

    def _ready(self) -> float | None:
        """Under the lock: None when the head of the queue should run now, else how long to wait."""
        if not self._queue or self._held:
            return 1.0
        quiet = time.monotonic() - self._last
        if self._queue[0].jog and not self._flush and len(self._queue) < AHEAD_ITEMS:
            return None if quiet >= JOG_QUIET_S else JOG_QUIET_S - quiet
        gathering = self._rasters.growing and quiet < QUIET_S  # a raster row still coming
        head_runs = self._flush or (self._motion.enough and not gathering)
        if head_runs or len(self._queue) >= AHEAD_ITEMS:
            return None
        return None if quiet >= QUIET_S else QUIET_S - quiet

    def _ends_stream(self, generation: int, jog: bool) -> bool:
        """Under the lock: the open job (of jogs if `jog`) is closed (the sender quiet, a command
        that needs the machine at rest, a line of the other kind next, a reset)."""
        if self._flush or self._stale(generation) or (self._queue and self._queue[0].jog != jog):
            return True
        return not self._queue and time.monotonic() - self._last >= STREAM_QUIET_S

    def _feed(self, run: JobRun, last: Work, generation: int) -> Work:
        """The lines that come while `run` runs, added to it while it is not too far ahead of the
        board, until the stream ends (then it is closed) or the job does; the last work added."""
        jog = last.jog
        most = JOG_AHEAD_S if jog else AHEAD_S  # planned motion ahead of the board
        while run.end is None:
            with self._cond:
                self._cond.wait(POLL_S)
                if self._ends_stream(generation, jog) or (not jog and self._rasters.holds_run):
                    break  # raster rows: a job of their own, once this one has come to rest
                quiet = time.monotonic() - self._last >= QUIET_S
                if (
                    not self._queue
                    or run.pending >= AHEAD_ITEMS
                    or (not jog and self._rasters.growing and not quiet)
                ):
                    continue
                progress = run.progress
                ahead = progress.seconds_left
                if progress.total - progress.done >= AHEAD_SEGMENTS:
                    continue
                if ahead >= most or not (
                    len(self._queue) >= ADD_LINES or ahead < most / 2 or quiet
                ):
                    continue
                works, cancels = [], self._jog_cancels
                while self._queue and self._queue[0].jog == jog:
                    works.append(self._queue.popleft())
                if not jog:
                    self._motion.clear()
                    self._rasters.clear()
                self._cond.notify_all()
            items = [item for work in works for item in work.items]
            if not run.extend(items, works[-1].line, works[-1].coordinates):
                with self._cond:  # the job ran to its end meanwhile: they start the next
                    cancelled = jog and self._jog_cancels != cancels
                    if not self._stale(generation) and not cancelled:
                        self._queue.extendleft(reversed(works))
                    self._cond.notify_all()
                return last
            last = works[-1]
        run.close()
        return last

    def _take(self) -> list[Work] | None:
        with self._cond:
            while not self._closed:
                wait = self._ready()
                if wait is None:
                    break
                self._cond.wait(wait)
            if self._closed:
                return None
            jog = self._queue[0].jog
            batch = []
            while self._queue and self._queue[0].jog == jog:
                batch.append(self._queue.popleft())
            self._batch_rasters = False
            if not jog:
                self._motion.clear()
                self._batch_rasters = self._rasters.holds_run
                self._rasters.clear()
            self._taking, self._taking_jog = True, jog
            self._taken_after = self._jog_cancels
            self._cond.notify_all()
            return batch

    def _loop(self) -> None:
        while True:
            batch = self._take()
            if batch is None:
                return
            try:
                self._run(batch)
            except (JobError, MachineError, LinkError) as exc:
                self.on_fault(str(exc))
            finally:
                with self._cond:
                    self._running, self._taking = None, False
                    self._cond.notify_all()

    def _run(self, batch: list[Work]) -> None:
        items = [item for work in batch for item in work.items]
        machine = self.machine
        last = batch[-1]
        with self._cond:
            generation = self.generation
            open_end = not self._batch_rasters  # rasters: planned whole
        if items:
            program = Program(items=items, lines=last.line, coordinates=last.coordinates)
            feed = 100 if last.jog else self.feed_override
            start = machine.position
            overrides = machine.speed_overrides.at(feed) if not last.jog else Overrides()
            scaled = apply_overrides(program, overrides, machine.config, start)
            plan = plan_program(scaled, machine.config, start, "line")
            with self._cond:  # a feed hold before it starts waits for cycle start; a reset drops it
                self._cond.wait_for(lambda: not self._held or self._stale(generation))
                if self._stale(generation) or (last.jog and self._jog_cancels != self._taken_after):
                    return
                run = machine.run_job(
                    plan,
                    program,
                    label="line",
                    feed_override=feed,
                    open_end=open_end,
                    overridden=True,  # a jog's moves all have a feed and no S
                    open_floor_s=JOG_FLOOR_S if last.jog else FLOOR_S,
                )
                self._running = Running(run, last.jog)
            if open_end:
                last = self._feed(run, last, generation)
            end = run.wait()
            if end is not None and end.ended_by == "error":
                raise MachineError(end.error or "the job failed")
        if machine.coordinates != last.coordinates:
            machine.adopt_coordinates(last.coordinates)
