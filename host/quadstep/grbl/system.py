"""GRBL's `$` commands for one sender's session: settings (`$$`, `$N=value`, `$10`), reports
(`$#`, `$G`, `$I`), jogs (`$J=`), and those that wait for the machine to rest (`$H`, `$X`, `$C`,
`$SLP`, `$RST=#`). Each returns the lines that answer it."""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from ..coordinates import WorkCoordinates
from ..link import LinkError
from ..machine import Machine, MachineError
from ..machine.homing import home
from ..planner.program import OutputState
from ..protocol import State
from .alarms import homing_alarm
from .errors import GrblError
from .executor import Executor, Work
from .probe import ProbeReport
from .protocol import OPTIONS, VERSION
from .reader import JogError, Reader
from .settings import NOT_KEPT, settings_lines
from .settings_write import (
    STATUS_MASK,
    SettingError,
    SettingWrite,
    changes,
    parse_write,
    write_setting,
)
from .status import StatusMask

HELP = "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]"
SLEEPING = "[MSG:Sleeping]"
Answer = list[str]


def message(text: str) -> str:
    return f"[MSG:{text.replace('[', '(').replace(']', ')')}]"


class SessionState(Protocol):
    """What the `$` commands read and change of a session."""

    machine: Machine
    reader: Reader
    reader_lock: threading.Lock  # held while a line or a report reads or changes the modal state
    executor: Executor
    config_path: Path | None  # where settings writes go (None: no configuration file)
    status_mask: StatusMask
    last_probe: ProbeReport
    alarm: bool
    board_alarm: bool  # the firmware raised an alarm; $X clears it
    check_mode: bool
    homing: bool
    probing: bool
    sleeping: bool


def system_command(session: SessionState, text: str, generation: int) -> Answer:
    """A line that begins with `$`."""
    command = text[1:].upper()
    if command.startswith("J="):
        return _jog(session, text[3:], generation)
    answer = _commands(session, generation).get(command)
    if answer is not None:
        return answer()
    try:
        write = parse_write(text)
        if write is not None:
            return _write_setting(session, write)
    except SettingError as exc:
        return [message(str(exc)), f"error:{exc.error.value}"]
    if command.startswith(("N", "RST=")):
        return [NOT_KEPT, f"error:{GrblError.INVALID_STATEMENT.value}"]
    return [f"error:{GrblError.INVALID_STATEMENT.value}"]


def _commands(session: SessionState, generation: int) -> dict[str, Callable[[], Answer]]:
    """`$` commands by name, each answering when called."""
    machine = session.machine
    return {
        "": lambda: [HELP, "ok"],
        "$": lambda: [*settings_lines(machine.config, session.status_mask.value), "ok"],
        "I": lambda: [VERSION, OPTIONS, "ok"],
        "#": lambda: [
            *_read(session, lambda: session.reader.offsets_report(session.last_probe.line())),
            "ok",
        ],
        "G": lambda: [*_read(session, lambda: [session.reader.modal_report()]), "ok"],
        "N": lambda: ["$N0=", "$N1=", "ok"],
        "SLP": lambda: _sleep(session, generation),
        "RST=#": lambda: _clear_offsets(session, generation),
        "X": lambda: _unlock(session, generation),
        "H": lambda: _home(session, generation),
        "C": lambda: _check_mode(session, generation),
    }


def _read(session: SessionState, report: Callable[[], list[str]]) -> list[str]:
    """A report of the modal state, taken while no line is being read."""
    with session.reader_lock:
        return report()


def _write_setting(session: SessionState, write: SettingWrite) -> Answer:
    """At rest (GRBL's error 8 else): the setting into the file, used from the next line."""
    if not session.executor.idle or session.homing or session.probing:
        return [f"error:{GrblError.NOT_IDLE.value}"]
    if write.number == STATUS_MASK:
        return _write_status_mask(session, write)
    machine = session.machine
    if write_setting(machine, session.config_path, write):
        with session.reader_lock:
            session.reader.reconfigure(machine.config, machine.position_mm)
    return ["ok"]


def _write_status_mask(session: SessionState, write: SettingWrite) -> Answer:
    """$10: what the reports carry, from the next one, for every sender of this server; kept in
    the configuration file ([senders] status_mask) for the next, as GRBL keeps it in EEPROM
    (without a file, for as long as this server runs)."""
    if session.config_path is not None:
        write_setting(session.machine, session.config_path, write)
    else:
        changes(session.machine.config, write)  # the value checked
    session.status_mask.value = int(write.value)
    return ["ok"]


def _jog(session: SessionState, text: str, generation: int) -> Answer:
    """$J=: only when idle or jogging (GRBL's error 8 else, in an alarm too)."""
    executor = session.executor
    if session.alarm or (not executor.idle and not executor.jogging):
        return [f"error:{GrblError.NOT_IDLE.value}"]
    try:
        with session.reader_lock:
            read = session.reader.jog(text)
    except JogError as exc:
        return [message(str(exc)), f"error:{GrblError.INVALID_JOG.value}"]
    executor.submit(Work(read.items, read.coordinates, read.line, jog=True), generation)
    return ["ok"]


def _sleep(session: SessionState, generation: int) -> Answer:
    """$SLP, as GRBL: at rest, the spindle (laser) and coolant off, then Sleep until a soft reset,
    which leaves an alarm ($X or $H unlocks)."""
    if not session.executor.wait_idle(generation):
        return []
    off = OutputState()
    with session.reader_lock:
        if session.reader.interpreter.outputs != off:
            session.machine.set_outputs(off)
            session.reader.interpreter.outputs = off
    session.sleeping = True
    return ["ok", SLEEPING]


def _clear_offsets(session: SessionState, generation: int) -> Answer:
    """$RST=#, as GRBL: at rest, G54–G59's offsets and the G28/G30 positions back to zero (G92 and
    the tool length stay, as GRBL keeps neither with them)."""
    if not session.executor.wait_idle(generation):
        return []
    with session.reader_lock:
        kept = session.reader.coordinates
        cleared = WorkCoordinates(
            system=kept.system, g92=kept.g92, g92_applied=kept.g92_applied, tlo=kept.tlo
        )
        session.machine.adopt_coordinates(cleared)
        session.reader.reset_coordinates(cleared)
    return ["ok"]


def _unlock(session: SessionState, generation: int) -> Answer:
    if not session.executor.wait_idle(generation):
        return []
    if session.machine.status().state == State.ALARM:
        session.machine.emergency_stop()  # at rest already: a STOP clears the board's alarm
    session.alarm = session.board_alarm = False
    return ["[MSG:Caution: Unlocked]", "ok"]


def _home(session: SessionState, generation: int) -> Answer:
    machine = session.machine
    if not any(a.homing is not None for a in machine.config.axes):
        return [f"error:{GrblError.HOMING_DISABLED.value}"]
    if not session.executor.wait_idle(generation):
        return []
    session.homing = True
    try:
        home(machine)
    except (MachineError, LinkError) as exc:
        session.alarm = True
        return [message(str(exc)), f"ALARM:{homing_alarm(str(exc)).value}", "ok"]
    finally:
        session.homing = False
    session.alarm = False
    with session.reader_lock:
        session.reader.resync(machine.position_mm)
    return ["ok"]


def _check_mode(session: SessionState, generation: int) -> Answer:
    if not session.executor.wait_idle(generation):
        return []
    session.check_mode = not session.check_mode
    if session.check_mode:
        return ["[MSG:Enabled]", "ok"]
    with session.reader_lock:  # leaving check mode resets the modal state, as a soft reset does
        session.reader.reset(session.machine.position_mm, session.machine.coordinates)
    return ["[MSG:Disabled]", "ok"]
