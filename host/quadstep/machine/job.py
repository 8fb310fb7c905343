"""A planned job on its way to the board, run by a thread of its own through the states of
job_state.py.

The plan is streamed section by section: an M0 (or a move file's pause) ends a section at rest, and
the job waits there (PAUSED) until resume(). A feed hold brings it to rest (HELD) until resume(); a
board that ran dry brakes to rest by itself (STARVED) and the job goes on at once. In each case what
is left is planned again from where the machine rests (RESUMING). A feed override plans the rest
again while the board keeps moving (OVERRIDING), a G38.x of the program hands the machine to the
probe (PROBING). halt() brings the machine to rest with HOLD and ends the job (STOPPED).
Machine.run_job starts one; the CLI and the TUI both run jobs this way.
"""

from __future__ import annotations

import threading
from array import array
from bisect import bisect_left
from collections.abc import Callable, Sequence
from dataclasses import replace
from itertools import accumulate
from typing import TypeVar

from ..coordinates import WorkCoordinates
from ..link import Link, LinkError
from ..planner.feed_override import Overrides, apply_overrides, check_percent
from ..planner.plan import Plan, plan_program
from ..planner.program import Item, JobError, Pause, ProbeMove, Program
from ..protocol import InputCause, InputChange, Outputs, Report
from .errors import MachineError
from .job_legs import (
    PauseOffer,
    base_plan,
    rest_after_pause,
    rest_after_probe,
    rest_after_stop,
    stream_move_ends,
)
from .job_outputs import FEED_HOLD, outputs_at, spindle_stopped, stream_outputs, switch_off
from .job_state import JobProgress, JobState, JobStates
from .journal import Journal
from .motion import STARVED, Motion, MotionEnd
from .move_items import MoveItems
from .open_end import FLOOR_S, OpenEnd, settled_moves
from .override import Swap, replan_running
from .rebase import Rebase, find, rebased
from .restream import Restream
from .speed_overrides import SpeedOverrides
from .takeups import StreamPlan

PauseOrProbe = TypeVar("PauseOrProbe", Pause, ProbeMove)
LOOKAHEAD_S = (
    0.5  # s queued beyond the watchdog's host_timeout: a lost host meets the watchdog first
)
# how a section's streaming comes back while its motion goes on: cut where a new plan takes over
CUT = "cut"
ADDITION_POLL_S = 0.005  # s between looks at lines added and not planned yet, while the board runs
AT_REST = (
    FEED_HOLD,
    STARVED,
)  # motion ends after which the rest of the job is planned again from rest


def final_state(end: MotionEnd) -> JobState:
    if end.ended_by == "done":
        return JobState.DONE
    return JobState.FAILED if end.ended_by in ("error", STARVED) else JobState.STOPPED


class JobRun:
    """One planned job on one link: start() it, then wait(), resume() after a pause or a feed hold,
    or halt().

    With the job's `program` (and a machine's `restream`), a feed hold or a board that ran dry keeps
    the rest of the job, and set_feed_override() scales the feeds of what is not yet sent (the plan
    given is planned at `feed_override` % and at the rapid and spindle overrides of
    `speed_overrides`, whose changes reach the job through overrides_changed()). Without it a feed
    hold or running dry ends the job, as halt() does."""

    def __init__(
        self,
        link: Link,
        plan: Plan | StreamPlan,
        decels: tuple[int, ...],
        *,
        program: Program | None = None,
        label: str = "line",
        feed_override: int = 100,
        speed_overrides: SpeedOverrides | None = None,
        restream: Restream | None = None,
        busy_elsewhere: Callable[[], bool] | None = None,
        journal: Journal | None = None,
        open_end: bool = False,
        open_floor_s: float = FLOOR_S,
    ) -> None:
        self.link = link
        self.plan = plan
        self.program = program
        self.label = label
        self.decels = decels
        # the machine's: positions, take-ups and probing for a job that goes on
        self.restream = restream
        self.busy_elsewhere = busy_elsewhere  # the machine's: another program runs at a pause
        self.journal = journal  # where each leg of the job is kept for `run --resume`
        self.on_end: Callable[[MotionEnd], None] | None = None  # called once, in the job's thread
        self.settle: Callable[[MotionEnd], MotionEnd] | None = None  # the machine's view of the end
        self.states = JobStates(on_change=self._note_state)
        self.lookahead = round((plan.config.host_timeout + LOOKAHEAD_S) * plan.config.tick_hz)
        self._ticks = array("q", accumulate(plan.segments.n, initial=0))  # 8 bytes a segment
        self._done_before = 0  # segments of the job run before the plan now streamed (a re-plan)
        self._lock = threading.Lock()
        self._resume = threading.Event()
        self._ended = threading.Event()
        self._end: MotionEnd | None = None
        # how the last leg came to rest (a feed hold, a queue run dry)
        self._rest: MotionEnd | None = None
        self._halted: str | None = None  # the reason halt() was given
        self._motion: Motion | None = None
        self._offset = 0  # segments of the sections before the current one
        self._interrupted = False  # other programs ran while the job waited at its pause
        self._override = check_percent(feed_override)  # the feed override wanted, %
        self._speeds = speed_overrides  # the rapid and spindle overrides wanted (the machine's)
        self._planned = self._wanted()  # those the plan has from the first segment not sent on
        self._swap: Swap | None = None  # the plan to go on with where the running motion was cut
        self._rebase: Rebase | None = None  # where the swap's plan begins in the running one
        self._wake = threading.Event()  # the motion ended, or an override changed
        # a job that extend() adds to while it runs (a sender's stream), and the program's items the
        # plan covers (those after them were added and are planned next)
        self._open_end = (
            OpenEnd(plan.config, open_floor_s) if open_end and program is not None else None
        )
        self._planned_items = len(program.items) if program is not None else 0
        self._swap_items = 0  # the program's items the swap waiting to be streamed covers
        # where the leg's moves are in its program, for planning its rest again from a move
        self._move_items = MoveItems(plan.config, base_plan(plan).start)
        self._thread = threading.Thread(target=self._run, name="quadstep-job", daemon=True)

    # --- what the job is doing ---------------------------------------------------------------

    @property
    def state(self) -> JobState:
        return self.states.state

    @property
    def progress(self) -> JobProgress:
        with self._lock:  # one leg's plan, ticks and counts (a re-plan swaps them together)
            motion, offset, plan = self._motion, self._offset, self.plan
            ticks, before = self._ticks, self._done_before
        state, line_at = self.states.snapshot()
        total = len(plan)
        done = min(total, max(0, offset + (motion.done if motion is not None else 0)))
        line = int(plan.segments.line[min(done, total - 1)]) if total else 0
        left = (ticks[-1] - ticks[done]) / plan.config.tick_hz
        return JobProgress(
            before + done, before + total, line, left, line_at, state, self.states.starvations
        )

    @property
    def held(self) -> bool:
        """At rest after a feed hold, waiting for resume()."""
        return self.state is JobState.HELD

    @property
    def paused_at(self) -> int | None:
        """The line of the pause or feed hold the job waits at, if it does."""
        return self.states.line

    @property
    def pause(self) -> Pause | None:
        """What the job waits at, when it waits at an M0 or a tool change (M6: `tool`) of its
        program."""
        state, line = self.states.snapshot()
        return self._item_at(Pause, line) if state is JobState.PAUSED and line is not None else None

    @property
    def end(self) -> MotionEnd | None:
        return self._end

    @property
    def last_rest(self) -> MotionEnd | None:
        """How the job last came to rest on the way (a feed hold: its hold_tick and decelerations),
        if it has."""
        return self._rest

    @property
    def feed_override(self) -> int:
        """The feed override, % (100: the feeds as programmed)."""
        return self._override

    @property
    def gives_way(self) -> bool:
        """Waiting at a pause of its program (M0, a tool change) or probing for it on a machine:
        jogs, probing and work zeros may run meanwhile, and the job goes on from where they leave
        the machine."""
        return (
            self.state in (JobState.PAUSED, JobState.PROBING)
            and self.restream is not None
            and self.program is not None
            and not self._halted
        )

    # --- control ------------------------------------------------------------------------------

    def start(self) -> JobRun:
        self._thread.start()
        return self

    def wait(self, timeout: float | None = None) -> MotionEnd | None:
        """How the job ended (`done`, the reason given to halt(), `reset`, or `error`); None on
        timeout."""
        self._ended.wait(timeout)
        return self._end

    def set_feed_override(self, percent: int) -> int:
        """Scale every feed (not the rapids) of what is not yet sent by `percent` (10–200,
        ValueError outside): the rest of the job is planned again from the first move boundary not
        sent and streamed in place of the old without a stop (from the next pause when the section
        under way has no boundary left)."""
        check_percent(percent)
        with self._lock:
            self._override = percent
        self._wake.set()
        return percent

    def overrides_changed(self) -> None:
        """The rapid or spindle override changed: what is not yet sent is planned again at it, as
        for set_feed_override()."""
        self._wake.set()

    def _wanted(self) -> Overrides:
        """The overrides wanted now."""
        if self._speeds is None:
            return Overrides(self._override)
        return self._speeds.at(self._override)

    def interrupt(self) -> None:
        """Another program is about to run while the job waits (the machine calls this, gives_way
        being true): the machine takes the job's place and band at the pause as where it stands."""
        with self._lock:
            first, self._interrupted = not self._interrupted, True
        if first and self.restream is not None:
            self.restream.at_rest()

    def resume(self) -> bool:
        """Go on after a pause or a feed hold; False when the job waits at neither, or another
        program runs."""
        if self.busy_elsewhere is not None and self.busy_elsewhere():
            return False
        if not (
            self.states.leave(JobState.PAUSED, JobState.RESUMING)
            or self.states.leave(JobState.HELD, JobState.RESUMING)
        ):
            return False
        self._resume.set()
        return True

    def feed_hold(self) -> bool:
        """Bring the machine to rest (HOLD) and keep the rest of the job for resume(); False when
        nothing moves."""
        with self._lock:
            motion = self._motion if not self._halted else None
        if motion is None or self.program is None:
            return False
        motion.halt(FEED_HOLD)
        return True

    def stop_spindle(self, stop: bool) -> bool:
        """At a feed hold: the spindle (or laser) off, the coolant kept (`stop`), or on again as the
        job had it. resume() brings it back in any case: the rest is planned from the hold with the
        outputs the program set. False when the job is not held or sets no outputs."""
        if not self.held:
            return False
        message = outputs_at(self.plan, self._offset)
        if message is None:
            return False
        self.link.send(spindle_stopped(message) if stop else message)
        return True

    def extend(
        self, items: Sequence[Item], lines: int, coordinates: WorkCoordinates | None = None
    ) -> bool:
        """Add `items` to the end of an open job (started with `open_end`): they are planned onto
        what is not yet sent, without a stop where the board has not been sent the end (else from
        where the machine comes to rest). False when the job takes no more (closed, ended, halted):
        they belong to a new job."""
        if (
            self._open_end is None
            or self._halted
            or not self._open_end.add(items, lines, coordinates)
        ):
            return False
        self._wake.set()
        return True

    def close(self) -> None:
        """No more lines come for now: the plan runs to its end, where the machine rests, and the
        job ends there (DONE)."""
        if self._open_end is None:
            return
        with self._lock:
            self._open_end.close()
            motion = self._motion
        if motion is not None:
            motion.hold_back(None)

    @property
    def open(self) -> bool:
        """extend() may still add to the job."""
        return self._open_end is not None and self._open_end.open and not self._halted

    @property
    def pending(self) -> int:
        """Items added and not yet planned."""
        if self._open_end is None or self.program is None:
            return 0
        return self._open_end.pending + len(self.program.items) - self._planned_items

    def halt(self, reason: str = "stop") -> MotionEnd:
        """Bring the machine to rest (HOLD) and end the job; returns how it ended."""
        with self._lock:
            self._halted = self._halted or reason
            motion = self._motion
        self._resume.set()
        if motion is not None:
            motion.halt(reason)
        end = self.wait()
        assert end is not None
        return end

    # --- the job's thread ----------------------------------------------------------------------

    def _run(self) -> None:
        unregister = self.link.on_report(self._on_report)
        try:
            self._begin_leg()
            end = self._sections()
            while self.program is not None and not self._halted:
                if end.ended_by in AT_REST:
                    end = self._after_rest(end)
                elif end.ended_by == "done" and self._goes_on():
                    end = self._more_from_rest()
                else:
                    break
        except (LinkError, JobError, MachineError) as exc:
            end = MotionEnd("error", (), self._offset, error=str(exc))
        finally:
            unregister()
        end = switch_off(self.link, end, bool(stream_outputs(self.plan)))
        if self.settle is not None:
            end = self.settle(end)
        self._end = end
        self.states.enter(final_state(end))
        if self.on_end is not None:
            self.on_end(end)
        self._ended.set()

    def _after_rest(self, rest: MotionEnd) -> MotionEnd:
        """At rest after a feed hold (wait for resume()) or after the board ran dry (go on at once):
        plan what is left from here and stream it."""
        at = min(self._offset, len(self.plan) - 1)
        self._rest = rest
        if rest.ended_by == STARVED:
            self.states.enter(JobState.STARVED)
            self.states.enter(JobState.RESUMING)
        else:
            self.states.enter(JobState.HELD, int(self.plan.segments.line[at]))
            self._resume.wait()
            self._resume.clear()
        with self._lock:
            if self._halted:
                return replace(
                    rest, ended_by=self._halted, segments_done=self._done_before + self._offset
                )
        assert self.program is not None
        if self.restream is not None:  # the machine's positions, the band where the stop left it
            here = self.restream.held(rest)
        else:
            here = tuple(self.link.status().position[: self.plan.segments.axis_count])
        self.program = rest_after_stop(self.program, self.plan, self._offset, self._move_items)
        return self._next_leg(here)

    def _goes_on(self) -> bool:
        """Everything planned has run: an open job goes on when more was added meanwhile."""
        if self._open_end is None or self.program is None:
            return False
        return self._open_end.go_on(len(self.program.items) > self._planned_items)

    def _more_from_rest(self) -> MotionEnd:
        """The lines added after the board was sent the end of the plan: from where it rests."""
        assert self.program is not None
        if self.state is not JobState.RESUMING:
            self.states.enter(JobState.RESUMING)
        if self.restream is not None:
            here = self.restream.at_rest()
        else:
            here = tuple(self.link.status().position[: self.plan.segments.axis_count])
        self.program = self._move_items.rest_of(self.program, self._planned_items)
        return self._next_leg(here)

    def _scaled(self, here: tuple[int, ...]) -> Program:
        """The program to plan from `here` (what is left of the job) at the overrides wanted now."""
        assert self.program is not None
        with self._lock:
            self._planned = self._wanted()
        return apply_overrides(self.program, self._planned, base_plan(self.plan).config, here)

    def _item_at(self, kind: type[PauseOrProbe], line: int) -> PauseOrProbe | None:
        """The program's pause (or probe) at `line`."""
        for item in self.program.items if self.program is not None else ():
            if isinstance(item, kind) and item.line == line:
                return item
        return None

    def _probe(self, probe: ProbeMove) -> MotionEnd:
        """At rest before a G38.x of the program: the machine probes, then the rest of the program
        is read and planned from where the probe left it."""
        assert self.program is not None
        if self.restream is None or probe.resume is None:
            raise JobError(f"{self.label} {probe.line}: G{probe.code} probes only on a machine")
        with self._lock:
            if self._halted:
                return MotionEnd(self._halted, self.restream.position(), self._offset)
        self.states.enter(JobState.PROBING)  # the probe runs as the machine's program meanwhile
        rest_mm = self.restream.probe(probe)
        self.states.enter(JobState.RESUMING)
        self.program = rest_after_probe(self.program, probe, rest_mm)
        return self._next_leg(self.restream.position())

    def _after_pause(
        self, pause: Pause, before: WorkCoordinates, after: WorkCoordinates, interrupted: bool
    ) -> MotionEnd:
        """The operator jogged, probed or set a work zero at the pause: the rest of the program from
        where the machine stands, in the work offsets as they are now."""
        assert self.program is not None and self.restream is not None
        here = self.restream.at_rest() if not interrupted else self.restream.position()
        self.program = rest_after_pause(
            self.program, pause, before, after, base_plan(self.plan).config
        )
        return self._next_leg(here)

    def _next_leg(self, here: tuple[int, ...]) -> MotionEnd:
        """What is left of the program planned from `here` and streamed (its take-ups by the
        machine's), with what an open job was given meanwhile."""
        if self._open_end is not None and self.program is not None:
            self.program = self._open_end.merge(self.program)
            self._planned_items = len(self.program.items)
        remainder = plan_program(self._scaled(here), base_plan(self.plan).config, here, self.label)
        streamed = self.restream.stream(remainder) if self.restream is not None else remainder
        with self._lock:
            self._done_before += self._offset
            self.plan, self._offset = streamed, 0
            self._ticks = array("q", accumulate(streamed.segments.n, initial=0))
        self._move_items = MoveItems(remainder.config, remainder.start)
        self._begin_leg()
        return self._sections()

    def _begin_leg(self) -> None:
        """The plan now streamed is kept in the journal with the board's count of segments (at
        rest)."""
        if self.journal is not None and self.program is not None:
            base = base_plan(self.plan)
            self.journal.begin_leg(
                self.program,
                base.start,
                stream_move_ends(self.plan),
                len(self.plan),
                self.link.segments_done,
                self._planned.feed,
            )

    def _note_state(self, state: JobState) -> None:
        if self.journal is not None:
            self.journal.note(state, self.states.line)

    def _on_report(self, report: Report) -> None:
        """The board's cycle start button resumes a held job (in the reader thread: only an event is
        set)."""
        if isinstance(report, InputChange) and report.cause == InputCause.CYCLE_START and self.held:
            self.resume()

    def _sections(self) -> MotionEnd:
        """The plan streamed; where a feed override or lines added cut it short, the plan made then
        from where it was cut, streamed on by the same motion."""
        begin: int = 0
        follows: tuple[Motion, int] | None = None
        while True:
            end = self._sections_from(begin, follows)
            if end.ended_by != CUT or self._swap is None:
                # made as the motion ran out: what it planned is planned again
                self._swap, self._rebase = None, None
                return end
            swap, self._swap = self._swap, None
            rebase, self._rebase = self._rebase, None
            self._planned_items = max(self._planned_items, self._swap_items)
            # the new plan is the old one before the swap's index (from the rebase on, where it let
            # go of what ran): only the ticks after it are new
            if rebase is None:
                ticks = self._ticks[: swap.index + 1]
            else:
                kept = self._ticks[rebase.index : rebase.index + swap.index + 1]
                ticks = array("q", (t - rebase.ticks for t in kept))
                self._let_go(rebase, base_plan(swap.plan).start)
            n = swap.plan.segments.n
            ticks.extend(accumulate((n[i] for i in range(swap.index, len(n))), initial=ticks[-1]))
            ticks.pop(swap.index + 1)
            with self._lock:
                motion = self._motion
                self.plan, self._ticks = swap.plan, ticks
                if rebase is not None:
                    self._done_before += rebase.index
                    self._offset -= rebase.index
            assert motion is not None
            # the motion goes on with the new plan, its segment i being the new plan's i - shift
            begin, follows = swap.index, (motion, rebase.index if rebase is not None else 0)

    def _let_go(self, rebase: Rebase, start: tuple[int, ...]) -> None:
        """The program from the move under way where the plan now begins (`start`: the steppers
        there)."""
        assert self.program is not None
        first = self._move_items.item_of(self.program, rebase.moves - 1) + 1
        rest = self._move_items.rest_of(self.program, first)
        # the outputs in force there come first
        self._planned_items += len(rest.items) - len(self.program.items)
        self.program = rest
        self._move_items = MoveItems(base_plan(self.plan).config, start)

    def _stream(self, motion: Motion) -> MotionEnd:
        """Start `motion` (unless it goes on with a new plan) and wait for its end; meanwhile a
        changed feed override or lines added plan the rest again and cut the motion short where
        the new plan goes on (override.py): then a CUT end, the motion still streaming."""
        motion.on_end = lambda _end: self._wake.set()
        if self.state is not JobState.STREAMING:
            self.states.enter(JobState.STREAMING)
        if not motion.started:
            motion.start()
        while motion.end is None:
            if self._wanted() != self._planned:
                self._override_running(motion)
            elif self._extends(motion):
                self._extend_running(motion)
            if self._swap is not None:
                return MotionEnd(CUT, (), motion.sent)
            if motion.end is None:
                # lines waiting for enough company are looked at again as the board runs on
                self._wake.wait(ADDITION_POLL_S if self.pending else None)
                self._wake.clear()
        end = motion.wait()
        assert end is not None
        return end

    def _extends(self, motion: Motion) -> bool:
        """Lines were added while `motion` streams the last section (after a pause to come they
        are planned from that pause)."""
        open_end = self._open_end
        if open_end is None or not open_end.pending or motion.last != len(self.plan):
            return False
        # each addition plans the stop at the end again: worth it for as many lines as that, or
        # when that stop is about to be sent or run, or when no more lines come
        if open_end.pending >= open_end.batch or not open_end.open:
            return True
        identity = self.link.identity
        room = identity.queue_capacity if identity is not None else 1
        start, sent = self._tail_start(), motion.first + motion.sent
        done = min(max(motion.first + motion.done, 0), len(self._ticks) - 1)
        # the kept-back end goes to the board once it holds less than the floor before it
        near = open_end.floor_ticks + open_end.lead_ticks
        return start - sent < room or self._ticks[max(start, done)] - self._ticks[done] < near

    def _extend_running(self, motion: Motion) -> None:
        """The lines added, planned onto what `motion` has not sent (as a feed override plans the
        rest again) and swapped in where it is cut; where it has sent everything they wait for the
        end (_more_from_rest)."""
        assert self._open_end is not None and self.program is not None
        self.program = self._open_end.merge(self.program)
        # the moves before the stop at the end are planned as they would be again: from there on
        self._override_running(motion, overriding=False, start_at=self._tail_start())

    def _tail_start(self) -> int:
        """The first segment (as streamed) of the moves that lines added after the plan's end may
        change."""
        base = base_plan(self.plan)
        move = settled_moves(base)
        if move == 0:
            return 0
        first = base.move_ends[move - 1]
        if isinstance(self.plan, StreamPlan):
            return bisect_left(self.plan.segments.origin, first)
        return first

    def _override_running(self, motion: Motion, overriding: bool = True, start_at: int = 0) -> None:
        """An override changed while `motion` streams: plan the rest again (OVERRIDING) and have
        the new plan swapped in where the motion is cut."""
        if self.program is None:
            return
        if overriding:
            self.states.enter(JobState.OVERRIDING)
        running = self.restream if self.restream and isinstance(self.plan, StreamPlan) else None
        wanted, planned, config = self._wanted(), self._planned, base_plan(self.plan).config
        self._swap = replan_running(
            self.program,
            self.plan,
            motion,
            lambda program, start: apply_overrides(program, wanted, config, start),
            self.label,
            running.restream if running else None,
            self._ticks,
            start_at,
            # a jerk-limited plan is planned again whole: for an override, not for each added line
            (lambda program, start: apply_overrides(program, planned, config, start))
            if overriding
            else None,
            self._move_items,
        )
        if self._swap is not None:
            self._planned = wanted
            self._swap_items = len(self.program.items)
            if not overriding and self.journal is None:
                self._rebase_swap(motion)
            if running is not None:
                assert isinstance(self._swap.plan, StreamPlan)
                rebase = self._rebase
                if rebase is None:
                    running.swap(self._swap.plan)
                else:
                    running.swap(self._swap.plan, rebase.ticks, rebase.motor)
            if self.journal is not None:
                plan = self._swap.plan
                self.journal.replan(stream_move_ends(plan), len(plan), wanted.feed)
        if self.state is JobState.OVERRIDING:
            self.states.enter(JobState.STREAMING)

    def _rebase_swap(self, motion: Motion) -> None:
        """The swap's plan lets go of what the board has run, where it is long enough to
        (rebase.py): the running job's plan is kept from a segment boundary the board is past."""
        assert self._swap is not None
        done = min(motion.first + motion.done, self._swap.index - 1)
        self._rebase = find(self._swap.plan, self._ticks, done)
        if self._rebase is not None:
            index = self._swap.index - self._rebase.index
            self._swap = Swap(index, rebased(self._swap.plan, self._rebase))

    def _sections_from(self, begin: int, follows: tuple[Motion, int] | None) -> MotionEnd:
        """Each stretch of segments between pauses, from item `begin` on, and a wait at each pause
        (at the start or the end too). `follows`: the motion cut at `begin`, which goes on with
        this plan (its segment i being this plan's i − the shift given)."""
        total = len(self.plan)
        end: MotionEnd | None = None
        first = begin
        outputs = stream_outputs(self.plan)
        for section, (index, line) in enumerate([*self.plan.pauses, (total, None)]):
            if index < begin:
                continue
            mine = [(at, message) for at, s, message in outputs if s == section and at >= begin]
            if index > first or mine or follows is not None:
                with self._lock:
                    if self._halted and follows is None:
                        break
                    motion, first, going_on = self._section_motion(first, index, mine, follows)
                    self._motion, self._offset, follows = motion, first, None
                if not going_on:  # halted, or the board ran dry, as the new plan was made
                    halted = self._halted
                    end = motion.halt(halted) if halted else motion.wait()
                    assert end is not None
                    with self._lock:
                        self._motion = None
                        self._offset = first + end.segments_done
                    return end
                end = self._stream(motion)
                if end.ended_by == CUT:
                    return end  # the rest planned again: _sections goes on with it
                with self._lock:
                    self._motion = None
                    self._offset = index if end.ended_by == "done" else first + end.segments_done
                if end.ended_by != "done":
                    return (
                        end  # a feed hold or running dry among them: the caller plans what is left
                    )
                first = index
            if line is None:
                break
            probe = self._item_at(ProbeMove, line)
            if probe is not None:
                return self._probe(probe)
            gone_on = self._wait_at_pause(line)
            if gone_on is not None:
                return gone_on
        if end is not None and not self._halted:
            return end
        status = self.link.status()  # at rest: halted at a pause, or nothing to stream
        position = tuple(status.position[: self.plan.segments.axis_count])
        return MotionEnd(self._halted or "done", position, self._offset)

    def _section_motion(
        self,
        first: int,
        last: int,
        outputs: Sequence[tuple[int, Outputs]],
        follows: tuple[Motion, int] | None,
    ) -> tuple[Motion, int, bool]:
        """The motion that streams segments `first` … `last` with `outputs`: a new one, or the
        one cut at `first` going on with this plan, `follows` (with its shift); with its first
        segment (in this plan's numbering), and whether it goes on (False: it was halted, or the
        board ran dry, as the plan was made). An open job's end is kept back."""
        kept: int | None = None
        if last == len(self.plan) and self._open_end is not None:
            kept = self._open_end.kept_back(self._ticks)
        floor = self._open_end.floor_ticks if self._open_end is not None else 0
        if follows is not None:
            motion, shift = follows
            going_on = motion.go_on(self.plan.segments, shift, last, outputs, kept, floor)
            return motion, motion.first if going_on else motion.first - shift, going_on
        motion = Motion(
            self.link,
            self.plan.segments,
            self.decels,
            first=first,
            last=last,
            lookahead_ticks=self.lookahead,
            outputs=outputs,
        )
        motion.hold_back(kept, floor)
        return motion, first, True

    def _wait_at_pause(self, line: int) -> MotionEnd | None:
        """PAUSED at the pause of `line` until resume() or halt(); where the operator moved the
        machine or changed the work offsets meanwhile, the rest planned again from there (its end
        returned), else None: the next section follows as planned."""
        pause = self._item_at(Pause, line)
        with self._lock:
            if self._halted:
                return None
            self._interrupted = False
        self.states.enter(JobState.PAUSED, line)
        restream = self.restream
        program = pause.coordinates if pause is not None else None
        offer = (
            PauseOffer(program, restream) if program is not None and restream is not None else None
        )
        self._resume.wait()
        self._resume.clear()
        with self._lock:
            interrupted, halted = self._interrupted, self._halted
        after = offer.settle(interrupted, halted is not None) if offer is not None else None
        if after is not None and pause is not None and program is not None:
            return self._after_pause(pause, program, after, interrupted)
        if halted or pause is None or restream is None:
            return None
        if self._planned == self._wanted() and not self.pending:
            return None
        now = restream.coordinates()  # an override changed too late to be streamed: from here
        return self._after_pause(pause, now, now, interrupted)
