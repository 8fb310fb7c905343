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
from dataclasses import dataclass, field
from typing import Any, TypeVar

from ..config import MachineConfig, parse_config
from ..emulator import Emulator
from ..jog import Jogger, JogResult, JogSettings
from ..link import DEFAULT_BAUD, Link, LinkError
from ..protocol import IdentifyReply, StatusReport

T = TypeVar("T")

AXIS_NAMES = ("X", "Y", "Z", "A")
LINK_HEALTH = ("retransmits", "timeouts", "errors", "decode_errors", "alarms")


@dataclass(frozen=True)
class Target:
    """Where the machine is: a serial port, or an emulator this session starts (and restarts if it dies)."""

    port: str | None = None
    emulator: bool = False
    baud: int = DEFAULT_BAUD
    emulator_options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.emulator == (self.port is not None):
            raise ValueError("give either a serial port or the emulator")

    @property
    def label(self) -> str:
        return "emulator" if self.emulator else str(self.port)


@dataclass(frozen=True)
class Snapshot:
    """What the screen shows about the machine, read at one moment."""

    status: StatusReport
    link: dict[str, int]
    feed: float  # mm/min along the path since the previous snapshot
    position_mm: tuple[float, ...]


def default_config(tick_hz: int, axis_count: int) -> MachineConfig:
    """A configuration for a board nothing is known about: 80 steps/mm, ±1000 mm, gentle limits."""
    speed = min(100.0, math.floor(0.75 * tick_hz / 80))
    return parse_config({
        "tick_hz": tick_hz,
        "axes": [
            {"name": AXIS_NAMES[i], "steps_per_mm": 80, "max_speed": speed, "max_accel": 500,
             "travel_min": -1000, "travel_max": 1000}
            for i in range(axis_count)
        ],
    }, "default configuration")


class Session:
    """One machine; connect() again after the link is lost."""

    def __init__(
        self,
        target: Target,
        config: MachineConfig | None,
        settings: JogSettings | None = None,
        on_jog: Callable[[JogResult], None] | None = None,
    ) -> None:
        self.target = target
        self.config_given = config
        self.config: MachineConfig | None = config
        self.settings = settings or JogSettings()
        self.on_jog = on_jog
        self.link: Link | None = None
        self.jogger: Jogger | None = None
        self.emulator: Emulator | None = None
        self.identity: IdentifyReply | None = None
        self.lost: str | None = None
        self._commands = ThreadPoolExecutor(max_workers=1, thread_name_prefix="quadstep-command")
        self._pending: list[Future[Any]] = []
        self._lock = threading.Lock()
        self._last_feed_sample: tuple[int, tuple[int, ...]] | None = None

    # --- connection ----------------------------------------------------------------------

    @property
    def connected(self) -> bool:
        return self.link is not None and self.lost is None

    def connect(self) -> IdentifyReply:
        """Open the link (starting the emulator when it is not running) and set up jogging."""
        self.disconnect()
        if self.target.emulator and (self.emulator is None or not self.emulator.running):
            options = dict(self.target.emulator_options)
            if self.config_given is not None:
                options.setdefault("tick_hz", self.config_given.tick_hz)
                options.setdefault("axes", len(self.config_given.axes))
            self.emulator = Emulator(**options).start()
        url = self.emulator.url if self.emulator is not None else str(self.target.port)
        link = Link.open(url, self.target.baud)
        try:
            ident = link.identity
            assert ident is not None
            config = self.config_given or default_config(ident.tick_hz, ident.axis_count)
            if config.tick_hz != ident.tick_hz:
                raise LinkError(
                    f"the configuration's tick_hz = {config.tick_hz} differs from the firmware's {ident.tick_hz}"
                )
            if len(config.axes) > ident.axis_count:
                raise LinkError(
                    f"the configuration has {len(config.axes)} axes, the firmware {ident.axis_count}"
                )
            old = self.jogger
            jogger = Jogger(link, config, self.settings, on_finish=self.on_jog)
            if old is not None:
                jogger.mode, jogger.step_index, jogger.speed_index = old.mode, old.step_index, old.speed_index
        except BaseException:
            link.close()
            raise
        with self._lock:
            self.link, self.jogger, self.config, self.identity = link, jogger, config, ident
            self.lost = None
            self._last_feed_sample = None
        return ident

    def disconnect(self) -> None:
        with self._lock:
            link, self.link = self.link, None
        if link is not None:
            link.close()

    def close(self) -> None:
        """Bring any motion to rest, close the link and stop an emulator this session started."""
        self.cancel_pending()
        if self.connected and self.jogger is not None:
            try:
                self.jogger.stop()
            except LinkError:
                pass
        self._commands.shutdown(wait=False, cancel_futures=True)
        self.disconnect()
        if self.emulator is not None:
            self.emulator.stop()
            self.emulator = None

    def mark_lost(self, reason: str) -> None:
        with self._lock:
            if self.lost is None:
                self.lost = reason

    # --- reading ------------------------------------------------------------------------

    def snapshot(self) -> Snapshot:
        """Status, link counters and the feed since the last snapshot; raises LinkError when lost."""
        link, config = self.link, self.config
        if link is None or config is None or self.lost is not None:
            raise LinkError(self.lost or "not connected")
        try:
            status = link.status()
        except LinkError as exc:
            self.mark_lost(str(exc))
            raise
        position = tuple(status.position[: len(config.axes)])
        stats = link.stats.as_dict()
        return Snapshot(
            status=status,
            link={key: stats[key] for key in LINK_HEALTH},
            feed=self._feed(config, status.motion_ticks, position),
            position_mm=config.to_mm(position),
        )

    def _feed(self, config: MachineConfig, ticks: int, position: tuple[int, ...]) -> float:
        """mm/min over the motion ticks between two snapshots (the board's own time base)."""
        last, self._last_feed_sample = self._last_feed_sample, (ticks, position)
        if last is None or ticks <= last[0]:
            return 0.0
        distance = math.sqrt(sum(
            ((p - q) / axis.steps_per_mm) ** 2 for axis, p, q in zip(config.axes, position, last[1])
        ))
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

