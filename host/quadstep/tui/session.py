"""The TUI's connection to one machine: open, poll, lose and reopen, without the UI.

Every method here blocks on the serial line; the app calls them from worker
threads. Motion commands go through `submit`, which runs them one at a time
in arrival order, so jog key presses act in the order they were pressed.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from ..config import MachineConfig
from ..emulator import Emulator
from ..jog import Jogger, JogResult, JogSettings
from ..link import LinkError
from ..machine import JobRun, Machine, MotionEnd, Target, open_machine, start_emulator
from ..protocol import IdentifyReply, StatusReport

T = TypeVar("T")

LINK_HEALTH = ("retransmits", "timeouts", "errors", "decode_errors", "alarms")


@dataclass(frozen=True)
class Parting:
    """Where the machine was left when the session closed: the line a job was stopped at, and the
    rest."""

    machine: Machine
    line: int | None  # the job's line when its hold began (None: no job ran)
    label: str
    end: MotionEnd | None  # how the motion running then ended (None: nothing moved)


@dataclass(frozen=True)
class Snapshot:
    """What the screen shows about the machine, read at one moment."""

    status: StatusReport
    link: dict[str, int]
    feed: float  # mm/min along the path since the previous snapshot
    position_mm: tuple[float, ...]  # machine coordinates
    work_mm: tuple[float, ...]  # in the active work system
    system: str  # G54 … G59
    steps: tuple[int, ...] = ()  # machine position in steps, the backlash's take-ups excluded


class Session:
    """One machine; connect() again after the link is lost."""

    def __init__(
        self,
        target: Target | None,
        config: MachineConfig | None,
        settings: JogSettings | None = None,
        on_jog: Callable[[JogResult], None] | None = None,
        config_source: str = "the configuration",
        state_file: Path | None = None,
        config_path: Path | None = None,
    ) -> None:
        self.target = target  # None until the port picker chose one
        self.config_given = config
        self.config_source = config_source
        self.config_path = config_path  # where a measured backlash is written (tui/confirm.py)
        self.state_file = state_file  # the work coordinates, kept across runs (machine/state.py)
        self.config: MachineConfig | None = config
        self.settings = settings or JogSettings()
        self.on_jog = on_jog
        self.machine: Machine | None = None
        self.jogger: Jogger | None = None
        self.emulator: Emulator | None = None  # kept across reconnections, started anew when gone
        self.identity: IdentifyReply | None = None
        self.lost: str | None = None
        self._commands = ThreadPoolExecutor(max_workers=1, thread_name_prefix="quadstep-command")
        self._pending: list[Future[Any]] = []
        self._lock = threading.Lock()
        self._last_feed_sample: tuple[int, tuple[int, ...]] | None = None
        self.parting: Parting | None = None  # set by close()
        # the terminal reports key releases (kitty.py); without them a jog press is a tap
        self.key_releases = False

    # --- connection ----------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        return self.machine is not None and self.lost is None

    def connect(self) -> IdentifyReply:
        """Open the machine (starting the emulator when it is not running) and set up jogging."""
        self.disconnect()
        if self.target is None:
            raise LinkError("no port chosen")
        if self.target.emulator and (self.emulator is None or not self.emulator.running):
            self.emulator = start_emulator(self.target, self.config_given)
        machine = open_machine(
            self.target,
            self.config_given,
            source=self.config_source,
            emulator=self.emulator,
            state_file=self.state_file,
        )
        old = self.jogger
        jogger = Jogger(machine, self.settings, on_finish=self.on_jog)
        jogger.taps = not self.key_releases
        if old is not None:
            jogger.copy_presets(old)
        with self._lock:
            self.machine, self.jogger, self.config, self.identity = (
                machine,
                jogger,
                machine.config,
                machine.identity,
            )
            self.lost = None
            self._last_feed_sample = None
        return machine.identity

    def disconnect(self) -> None:
        with self._lock:
            machine, self.machine = self.machine, None
        if machine is not None:
            # the link may be gone; close() brings motion to rest first
            machine.close(bring_to_rest=False)

    def close(self) -> None:
        """Bring any motion to rest, close the link and stop an emulator this session started;
        `parting` says where it was left."""
        self.cancel_pending()
        machine = self.machine
        if self.connected and machine is not None:
            program = machine.program
            job = program if isinstance(program, JobRun) else None
            line = job.progress.line if job is not None else None
            try:
                end = machine.hold("quit")
            except LinkError:
                end = None
            self.parting = Parting(machine, line, job.label if job is not None else "line", end)
        self._commands.shutdown(wait=False, cancel_futures=True)
        self.disconnect()
        if self.emulator is not None:
            self.emulator.stop()
            self.emulator = None

    def releases_reported(self) -> None:
        """The terminal reports key releases: a continuous jog runs from the press to the key-up."""
        self.key_releases = True
        if self.jogger is not None:
            self.jogger.taps = False

    def mark_lost(self, reason: str) -> None:
        with self._lock:
            if self.lost is None:
                self.lost = reason

    # --- reading ------------------------------------------------------------------------

    def snapshot(self) -> Snapshot:
        """Status, link counters and the feed since the last snapshot; raises LinkError when
        lost."""
        machine = self.machine
        if machine is None or self.lost is not None:
            raise LinkError(self.lost or "not connected")
        try:
            status = machine.status()
        except LinkError as exc:
            self.mark_lost(str(exc))
            raise
        config = machine.config
        position = machine.standing.live_position(status)
        stats = machine.stats.as_dict()
        position_mm = config.to_mm(position)
        coordinates = machine.coordinates
        return Snapshot(
            status=status,
            link={key: stats[key] for key in LINK_HEALTH},
            feed=self._feed(config, status.motion_ticks, position),
            position_mm=position_mm,
            work_mm=coordinates.to_work(config.axis_names, position_mm),
            system=coordinates.name,
            steps=position,
        )

    def _feed(self, config: MachineConfig, ticks: int, position: tuple[int, ...]) -> float:
        """mm/min over the motion ticks between two snapshots (the board's own time base)."""
        last, self._last_feed_sample = self._last_feed_sample, (ticks, position)
        if last is None or ticks <= last[0]:
            return 0.0
        distance = math.sqrt(
            sum(
                ((p - q) / axis.steps_per_mm) ** 2
                for axis, p, q in zip(config.axes, position, last[1])
            )
        )
        return distance / ((ticks - last[0]) / config.tick_hz) * 60.0

    # --- commands ------------------------------------------------------------------------

    def submit(self, command: Callable[[], T]) -> Future[T]:
        """Run `command` after every command submitted before it (one at a time, off the UI)."""
        future = self._commands.submit(command)
        with self._lock:
            self._pending = [f for f in self._pending if not f.done()] + [future]
        return future

    def cancel_pending(self) -> None:
        """Drop the commands that have not started yet (the stop key)."""
        with self._lock:
            pending, self._pending = self._pending, []
        for future in pending:
            future.cancel()
