"""Jogging: incremental steps and continuous moves that stop when the key is let go.

An incremental jog is a one-move Program planned like any job: exact, within
the limits, at rest at the end. A continuous jog is one move toward the soft
limit in the jog direction, streamed with little queued ahead; when the key
is released (no repeat in time, see release.py) or the stop key is pressed,
HOLD brings the machine to rest at each axis's max_accel and the position is
re-anchored where the board reports it rests. Left alone, the move ends at
rest exactly on the soft limit, so the limit holds by construction.

Positions are step positions, as the board counts them; distances are mm.
The machine (quadstep.machine) runs every jog and knows where it stands;
every blocking call talks to the board: call them from worker threads.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from ..config import MachineConfig
from ..link import LinkError
from ..machine import Machine, Motion, MotionEnd
from ..machine.units import step_direction, step_limits
from ..planner.plan import Plan, plan_program
from ..planner.program import JobError, LinearMove, Program
from .presets import JogMode, JogPresets
from .release import ReleaseDetector
from .settings import JogSettings
from .step_queue import QueuedStep, StepQueue, step_seconds

# s: how often a continuous jog's watcher looks at the motion besides its deadline
WATCH_INTERVAL = 0.05


@dataclass(frozen=True)
class JogResult:
    """One jog, from its start position to where the machine rests."""

    kind: JogMode
    axis: int
    direction: int  # +1 toward travel_max, −1 toward travel_min
    start: tuple[int, ...]
    target: tuple[int, ...]  # where the planned move ends (the soft limit for a continuous jog)
    end: MotionEnd | None  # None: nothing moved
    message: str = ""

    @property
    def position(self) -> tuple[int, ...]:
        return self.end.position if self.end is not None and self.end.position else self.start

    @property
    def stopped_by(self) -> str:
        return "nothing" if self.end is None else self.end.ended_by


class _Continuous:
    """A running continuous jog: its motion and the watcher that ends it on release."""

    def __init__(
        self,
        jogger: Jogger,
        axis: int,
        direction: int,
        motion: Motion,
        result: JogResult,
        first_timeout: float,
    ) -> None:
        self.jogger = jogger
        self.axis = axis
        self.direction = direction
        self.motion = motion
        self.template = result
        settings = jogger.settings
        self.release = ReleaseDetector(first_timeout, settings.repeat_timeout)
        self.release.press()
        self.thread = threading.Thread(target=self._watch, name="quadstep-jog-release", daemon=True)

    def _watch(self) -> None:
        released = False
        while True:
            remaining = self.release.deadline() - time.monotonic()
            if remaining <= 0:
                released = True
                break
            if self.motion.wait(min(remaining, WATCH_INTERVAL)) is not None:
                break
        end = self.motion.halt("release") if released else self.motion.wait()
        assert end is not None
        self.jogger._finish(self, end)


class Jogger(JogPresets):
    """Jogs one machine: step(), press(), stop(). Making one talks to nobody."""

    def __init__(
        self,
        machine: Machine,
        settings: JogSettings | None = None,
        on_finish: Callable[[JogResult], None] | None = None,
    ) -> None:
        super().__init__(machine.config, settings or JogSettings())
        self.machine = machine
        self.on_finish = on_finish
        self.last_result: JogResult | None = None
        self.queue = StepQueue()  # incremental presses waiting
        # A terminal that reports no key release: a press is a tap (a short step), and only its
        # key's repeats make the jog continuous (press()).
        self.taps = False
        self._tap: tuple[tuple[int, int], float] | None = None  # the last tap's key and time
        self._lock = threading.Lock()  # guards the fields below
        self._run_lock = threading.Lock()  # one motion at a time
        self._motion: Motion | None = None
        self._continuous: _Continuous | None = None
        self._idle = threading.Event()
        self._idle.set()
        self._commanded_mm: list[float] = [
            axis.to_mm(p) for axis, p in zip(self.config.axes, machine.position)
        ]

    @property
    def position(self) -> tuple[int, ...]:
        """Step positions where the machine last came to rest."""
        return self.machine.position

    @property
    def busy(self) -> bool:
        return not self._idle.is_set()

    def wait_idle(self, timeout: float | None = None) -> bool:
        """Wait until no jog runs; False on timeout."""
        return self._idle.wait(timeout)

    def anchor(self) -> None:
        """Re-anchor on where the machine layer says the machine stands (a job stopped at its
        pause)."""
        self._anchor(self.machine.position)

    def sync(self) -> None:
        """Read the board's position (machine at rest) and re-anchor on it."""
        self._anchor(self.machine.sync())

    # --- jogging ---------------------------------------------------------------------------

    def jog(self, axis: int, direction: int) -> JogResult | None:
        """A jog key: one step in incremental mode (blocks until at rest), a press in continuous
        mode."""
        if self.mode == JogMode.INCREMENTAL:
            return self.step(axis, direction)
        self.press(axis, direction)
        return None

    def step(self, axis: int, direction: int, distance: float | None = None) -> JogResult:
        """Move `axis` by `distance` mm (default: its selected preset) toward `direction`; blocks
        until at rest."""
        self._check_axis(axis, direction)
        with self._run_lock:
            self._idle.clear()
            try:
                return self._step(
                    axis, direction, self.distance_for(axis) if distance is None else distance
                )
            finally:
                self._idle.set()

    def queue_step(self, axis: int, direction: int) -> QueuedStep | None:
        """An incremental jog key: the step to run_queued() (in order, from a worker), or None when
        dropped because enough jog motion waits already (a held key's repeats)."""
        self._check_axis(axis, direction)
        distance = self.distance_for(axis)
        seconds = step_seconds(distance, self.speed(axis), self.config.axes[axis].max_accel)
        step = QueuedStep(axis, direction, distance, seconds)
        return step if self.queue.offer(step) else None

    def run_queued(self, step: QueuedStep) -> JogResult | None:
        """Run a step queue_step() took; None when a stop dropped it meanwhile."""
        if not self.queue.take(step):
            return None
        try:
            return self.step(step.axis, step.direction, step.distance)
        finally:
            self.queue.done(step)

    def press(self, axis: int, direction: int) -> None:
        """A press or repeat of a continuous jog key: starts the jog, or keeps it going."""
        self._check_axis(axis, direction)
        now = time.monotonic()
        settings = self.settings
        with self._lock:
            current = self._continuous
            if current is not None and (current.axis, current.direction) == (axis, direction):
                current.release.press()
                return
            last = self._tap
            repeat = last is not None and last[0] == (axis, direction)
            repeat = repeat and last is not None and now - last[1] <= settings.first_repeat_timeout
            tap = self.taps and current is None and not repeat
            self._tap = ((axis, direction), now) if tap else None
        if tap:
            # a tap: a short step; a repeat of its key within the first timeout goes on
            distance = min(settings.tap_max, self.speed(axis) * settings.tap_time)
            self.step(axis, direction, distance)
            return
        # started by a repeat (taps): the next repeat comes within the repeat timeout
        first = settings.repeat_timeout if self.taps else settings.first_repeat_timeout
        if current is not None:
            current.motion.halt("stop")  # another key: stop this jog first
            current.thread.join()
        self._run_lock.acquire()  # released when the jog ends (_finish)
        self._idle.clear()
        try:
            started = self._start_continuous(axis, direction, first)
        except BaseException:
            self._idle.set()
            self._run_lock.release()
            raise
        if not started:
            self._idle.set()
            self._run_lock.release()

    def release(self, axis: int, direction: int) -> bool:
        """The key of a continuous jog let go (a terminal that reports releases): HOLD now. False
        when no continuous jog of that key runs."""
        with self._lock:
            current = self._continuous
        if current is None or (current.axis, current.direction) != (axis, direction):
            return False
        current.motion.halt("release")
        return True

    def stop(self) -> JogResult | None:
        """The stop key: bring any jog to rest now (HOLD). Returns the ended jog, if one ran."""
        with self._lock:
            motion = self._motion
        self.queue.clear()
        if motion is None:
            return None
        motion.halt("stop")
        self.wait_idle()
        return self.last_result

    # --- internals -------------------------------------------------------------------------

    def _check_axis(self, axis: int, direction: int) -> None:
        if not 0 <= axis < len(self.config.axes):
            raise ValueError(f"axis {axis} is not configured (0 … {len(self.config.axes) - 1})")
        if direction not in (1, -1):
            raise ValueError(f"direction must be 1 or -1, not {direction}")

    def _step(self, axis: int, direction: int, distance: float) -> JogResult:
        cfg = self.config.axes[axis]
        start = self.position
        wanted_mm = round(self._commanded_mm[axis] + direction * distance, 9)
        target_steps = cfg.to_steps(wanted_mm)
        limited = self._limit(axis, direction, target_steps)
        message = ""
        if limited != target_steps:
            message = self._limit_message(axis, direction)
            wanted_mm = cfg.to_mm(limited)
        target = _replace(start, axis, limited)
        if (limited - start[axis]) * step_direction(cfg, direction) <= 0:
            if limited == target_steps:
                with self._lock:
                    # less than a step: remember it for the next
                    self._commanded_mm[axis] = wanted_mm
            return self._report(
                JogResult(JogMode.INCREMENTAL, axis, direction, start, start, None, message)
            )
        plan = self._plan(start, target, self.speed(axis))
        motion = self.machine.move(plan.segments)
        with self._lock:
            self._motion = motion
        end = motion.wait()
        assert end is not None
        with self._lock:
            self._motion = None
        self._settle(end)
        if end.ended_by == "done" and end.position == target:
            with self._lock:
                self._commanded_mm[axis] = wanted_mm
        return self._report(
            JogResult(
                JogMode.INCREMENTAL,
                axis,
                direction,
                start,
                target,
                end,
                message or _end_message(end),
            )
        )

    def _start_continuous(self, axis: int, direction: int, first_timeout: float) -> bool:
        cfg = self.config.axes[axis]
        start = self.position
        low, high = step_limits(cfg)
        limit = high if step_direction(cfg, direction) > 0 else low
        if (limit - start[axis]) * step_direction(cfg, direction) <= 0:
            self._report(
                JogResult(
                    JogMode.CONTINUOUS,
                    axis,
                    direction,
                    start,
                    start,
                    None,
                    self._limit_message(axis, direction),
                )
            )
            return False
        target = _replace(start, axis, limit)
        plan = self._plan(start, target, self.speed(axis))
        lookahead = round(self.settings.lookahead * self.config.tick_hz)
        motion = self.machine.move(plan.segments, lookahead_ticks=lookahead)
        template = JogResult(JogMode.CONTINUOUS, axis, direction, start, target, None)
        jog = _Continuous(self, axis, direction, motion, template, first_timeout)
        with self._lock:
            self._motion = motion
            self._continuous = jog
        jog.thread.start()
        return True

    def _finish(self, jog: _Continuous, end: MotionEnd) -> None:
        """Called by a continuous jog's watcher when the machine rests."""
        with self._lock:
            self._motion = None
            self._continuous = None
        self._settle(end)
        message = _end_message(end)
        if end.ended_by == "done":
            message = self._limit_message(jog.axis, jog.direction, reached=True)
        t = jog.template
        self._report(JogResult(t.kind, t.axis, t.direction, t.start, t.target, end, message))
        self._idle.set()
        self._run_lock.release()

    def _settle(self, end: MotionEnd) -> None:
        if end.position:
            self._anchor(self.machine.position)  # the machine took the rest position from the end
        else:
            try:
                self.sync()
            except LinkError:
                pass  # the link is gone; the next connection re-reads the position

    def _anchor(self, position: tuple[int, ...]) -> None:
        """Re-anchor on the machine's rest position: commanded coordinates follow wherever they
        disagree."""
        with self._lock:
            old = self._commanded_mm
            self._commanded_mm = [
                old[i] if i < len(old) and axis.to_steps(old[i]) == p else axis.to_mm(p)
                for i, (axis, p) in enumerate(zip(self.config.axes, position))
            ]

    def _limit(self, axis: int, direction: int, target: int) -> int:
        """`target` cut at the soft limit ahead (the one behind never pulls the machine along)."""
        cfg = self.config.axes[axis]
        low, high = step_limits(cfg)
        return min(target, high) if step_direction(cfg, direction) > 0 else max(target, low)

    def _limit_message(self, axis: int, direction: int, reached: bool = False) -> str:
        cfg = self.config.axes[axis]
        name, mm = (
            ("travel_max", cfg.travel_max) if direction > 0 else ("travel_min", cfg.travel_min)
        )
        sign = "+" if direction > 0 else "-"
        verb = "reached" if reached else "stops at"
        return f"{cfg.name}{sign}: {verb} the soft limit {name} = {mm:.3f} mm"

    def _plan(self, start: tuple[int, ...], target: tuple[int, ...], speed: float) -> Plan:
        config = _travel_including(self.config, start)
        move = LinearMove(line=1, target=config.to_mm(target), feed=speed)
        try:
            return plan_program(Program(items=[move], lines=1), config, start=start, label="jog")
        except JobError as exc:
            raise ValueError(f"cannot plan the jog: {exc}") from None

    def _report(self, result: JogResult) -> JogResult:
        self.last_result = result
        if self.on_finish is not None:
            self.on_finish(result)
        return result


def _replace(values: tuple[int, ...], index: int, value: int) -> tuple[int, ...]:
    return values[:index] + (value,) + values[index + 1 :]


def _travel_including(config: MachineConfig, position: tuple[int, ...]) -> MachineConfig:
    """The configuration with each axis's travel widened to contain `position`.

    Jogs check the soft limits themselves (only the limit ahead applies, so a
    machine outside its travel can always come back); the planner's own check
    would otherwise refuse every move while some axis stands outside.
    """
    axes = []
    for axis, steps in zip(config.axes, position):
        mm = axis.to_mm(steps)
        axes.append(
            axis.model_copy(
                update={
                    "travel_min": min(axis.travel_min, mm),
                    "travel_max": max(axis.travel_max, mm),
                }
            )
        )
    return config.model_copy(update={"axes": tuple(axes)})


def _end_message(end: MotionEnd) -> str:
    if end.error:
        return end.error
    if end.ended_by == "done":
        return ""
    if end.held:
        return f"{end.ended_by}: decelerated to rest (HOLD)"
    if end.ended_by == "reset":
        return "STOP: stopped at once"
    return f"{end.ended_by}: stopped at once (this firmware has no HOLD)"


__all__ = ["JogResult", "Jogger"]
