"""Where a machine is — a serial port, or the loopback emulator started for it — and opening it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..config import DEFAULT_CONFIG_NAME, MachineConfig
from ..default_machine import default_machine
from ..emulator import Emulator
from ..link import DEFAULT_BAUD, Link
from .machine import Machine
from .state_lock import StateLock


@dataclass(frozen=True)
class Target:
    """A serial port (a device, or socket://host:port), or an emulator with these options."""

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


def start_emulator(target: Target, config: MachineConfig | None) -> Emulator:
    """The emulator of `target`, ticking and with the axes `config` (or the default machine) asks
    for, unless its options say."""
    options = dict(target.emulator_options)
    config = config if config is not None else default_machine()
    options.setdefault("tick_hz", config.tick_hz)
    options.setdefault("axes", len(config.axes))
    return Emulator(**options).start()


def open_machine(
    target: Target,
    config: MachineConfig | None = None,
    *,
    source: str = "the configuration",
    emulator: Emulator | None = None,
    state_file: Path | None = None,
) -> Machine:
    """Connect to `target`. For an emulator target, `emulator` is a running one to use (its owner
    stops it); without it one is started, and the machine stops it when closed. `state_file` keeps
    the machine's state (machine.state.state_path gives the usual one); the machine holds its lock
    (state_lock.py), taken before anything connects, until closed."""
    label = source if config is not None else DEFAULT_CONFIG_NAME
    lock = StateLock.acquire(state_file, label) if state_file is not None else None
    started = None
    try:
        if target.emulator and emulator is None:
            emulator = started = start_emulator(target, config)
        url = emulator.url if target.emulator and emulator is not None else str(target.port)
        link = Link.open(url, target.baud)
        try:
            return Machine(
                link,
                config,
                source=source,
                emulator=started,
                state_file=state_file,
                state_lock=lock,
            )
        except BaseException:
            link.close()
            raise
    except BaseException:
        if started is not None:
            started.stop()
        if lock is not None:
            lock.release()
        raise
