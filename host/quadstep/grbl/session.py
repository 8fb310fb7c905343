"""One sender's conversation: its bytes in, GRBL's answers out.

Realtime commands are handled in the receiving thread as they arrive; lines go to a worker thread
that answers each one, in order, once it is checked and queued (executor.py) or done ($
commands)."""

from __future__ import annotations

import queue
import re
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ..coordinates import WorkCoordinates
from ..give_way import give_way
from ..link import LinkError
from ..link.inputs import input_status
from ..machine import Machine, MachineError
from ..machine.homing import home
from ..planner.program import JobError, OutputState, ProbeMove
from ..protocol import Alarm, Capability, InputChange, Report, State
from .alarms import FIRMWARE, fault_alarm, firmware_alarm, homing_alarm
from .errors import GrblAlarm, GrblError, error_for
from .executor import Executor, Work
from .outbox import Outbox, SenderPort
from .overrides import COOLANT_TOGGLES, OVERRIDE_BYTES, SPINDLE_STOP, Overrides, toggled
from .probe import ProbeHold, no_probe, run_probe, split_probe
from .protocol import (
    BANNER,
    CYCLE_START,
    FEED_HOLD,
    JOG_CANCEL,
    OPTIONS,
    SOFT_RESET,
    STATUS,
    VERSION,
    Line,
    Realtime,
    StreamSplitter,
)
from .reader import JogError, Reader
from .settings import NOT_KEPT, settings_lines
from .settings_write import SettingError, SettingWrite, parse_write, write_setting
from .status import StatusBuilder, StatusMask

HELP = "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]"
UNLOCK = "[MSG:'$H'|'$X' to unlock]"
Answer = list[str]
# Lines a sender has in flight (a character-counting one: up to 128 bytes) are read and queued
# one by one, and their answers written together once no more have arrived (one write and one
# turn for the link's threads, not one per line), at most this many at once.
ANSWERS_HELD = 16
PROGRAM_END = re.compile(r"M0*(2|30)(?![\d.])")
PGM_END = "[MSG:Pgm End]"
SLEEPING = "[MSG:Sleeping]"
STATUS_MASK_SETTING = 10
INPUT_CAPABILITIES = Capability.LIMIT_INPUTS | Capability.PROBE_INPUT | Capability.CONTROL_INPUTS


def may_wait(text: str) -> bool:
    """A system command, a probe or a program end, which may wait for the machine: the lines before
    it are answered first, as they would be by then."""
    squeezed = "".join(text.split()).upper()
    return squeezed.startswith("$") or "G38" in squeezed or PROGRAM_END.search(squeezed) is not None


def message(text: str) -> str:
    return f"[MSG:{text.replace('[', '(').replace(']', ')')}]"


@dataclass(frozen=True)
class SessionOptions:
    """How `quadstep grbl` was started: M6 "ignore" (GRBL's default) or "pause" (held until `~`,
    as quadstep's tool change); the configuration file that settings writes go to (None: none);
    $10, which its sessions share."""

    tool_change: str = "ignore"
    config_path: Path | None = None
    status_mask: StatusMask = field(default_factory=StatusMask)


class Session:
    """GRBL 1.1 on `machine` for one client, whose answers go out through `port`."""

    def __init__(
        self,
        machine: Machine,
        port: SenderPort,
        options: SessionOptions | None = None,
    ) -> None:
        self.machine = machine
        self.options = options = options if options is not None else SessionOptions()
        self._outbox = Outbox(port)
        self._reader_lock = threading.Lock()
        self.reader = Reader(
            machine.config, machine.position_mm, machine.coordinates, options.tool_change
        )
        self.executor = Executor(machine, self._fault)
        self.overrides = Overrides(machine, self.executor)
        self.status = StatusBuilder(self)
        self.splitter = StreamSplitter()
        self.alarm = machine.config.homing_required and not machine.homed
        self.check_mode = False
        self.homing = False
        self.probing = False
        self.sleeping = False  # $SLP: every line refused until a soft reset, which leaves an alarm
        self.probe_hold = ProbeHold()
        self.last_probe = no_probe(len(machine.config.axes))
        self._board_alarm = False  # the firmware raised an alarm; $X clears it
        self.status_mask = options.status_mask
        self.inputs_active = 0  # the board's inputs active now: read at start, then followed
        self._lines: queue.Queue[tuple[int, Line] | None] = queue.Queue()
        self._worker = threading.Thread(target=self._work, name="grbl-lines", daemon=True)
        self._unwatch = machine.on_report(self._on_report)

    def start(self, banner: bool = True) -> Session:
        """Serve; the banner unless the client's first bytes are a soft reset (which brings it)."""
        if banner:
            self._banner()
        self._read_inputs()
        self._worker.start()
        return self

    def close(self) -> None:
        """The client has gone: what moves comes to rest, the queue is dropped."""
        self._lines.put(None)
        self._unwatch()
        self.probe_hold.end()
        if self.homing or self.probing:
            self.machine.hold("quit")
        self.executor.close()
        self._worker.join(timeout=10)
        self._outbox.close()

    def say(self, *lines: str) -> None:
        text = "".join(f"{line}\r\n" for line in lines)
        self._outbox.put(text.replace("…", "...").encode("ascii", "replace"))

    def receive(self, data: bytes) -> None:
        """Bytes from the client (in its receiving thread)."""
        for event in self.splitter.feed(data):
            if isinstance(event, Realtime):
                self._realtime(event.byte)
            else:
                self._lines.put((self.executor.generation, event))

    # --- realtime ----------------------------------------------------------------------------

    def _realtime(self, byte: int) -> None:
        if byte == STATUS:
            self.say(self.status.report())
        elif byte == FEED_HOLD and self.probing:
            self.probe_hold.hold()  # the probe rests until cycle start
            self.machine.hold("feed hold")
        elif byte == FEED_HOLD:
            self.executor.feed_hold()
        elif byte == CYCLE_START:
            self.overrides.resumed()
            self.probe_hold.resume()
            self.executor.cycle_start()
        elif byte == SOFT_RESET:
            self._soft_reset()
        elif byte in OVERRIDE_BYTES:
            self.overrides.realtime(byte)
        elif byte == SPINDLE_STOP:
            self.overrides.spindle_stop()
        elif byte in COOLANT_TOGGLES:
            self._toggle_coolant(byte)
        elif byte == JOG_CANCEL and self.executor.cancel_jog():
            with self._reader_lock:
                self.reader.resync(self.machine.position_mm)

    def _toggle_coolant(self, byte: int) -> None:
        """0xA0 flood, 0xA1 mist: switched now at rest (and kept in the modal state, as M8/M7 and
        M9 would); ignored while anything moves or the firmware has no outputs."""
        if not self.executor.idle or self.homing or self.probing or self.check_mode:
            return
        with self._reader_lock:
            state = toggled(self.reader.interpreter.outputs, byte)
            try:
                self.machine.set_outputs(state)
            except (MachineError, LinkError):
                return
            self.reader.interpreter.outputs = state

    def _soft_reset(self) -> None:
        """0x18: a controlled stop (HOLD), the queue and the modal state dropped, then the banner;
        ALARM:3 when it stopped motion (the position is exact, but the sender's program was cut)."""
        self.splitter.clear()
        if self.sleeping:
            self.sleeping, self.alarm = False, True
        stopped = self.executor.reset()
        self.overrides.reset()
        self.probe_hold.end()
        if self.homing or self.probing:
            self.machine.hold("reset")
            stopped = True
        with self._reader_lock:
            self.reader.reset(self.machine.position_mm, self.machine.coordinates)
        self.check_mode = False
        if stopped:
            self.alarm = True
            self.say(f"ALARM:{GrblAlarm.RESET_IN_MOTION.value}")
        self._banner()

    def _banner(self) -> None:
        self.say("", BANNER)
        if self.alarm:
            self.say(UNLOCK)

    def _fault(self, text: str) -> None:
        """A batch that could not be planned or run (its lines were answered already): an alarm, so
        the sender stops (said once when the firmware's alarm said it already); $X unlocks."""
        self.alarm = True
        if self._board_alarm and firmware_alarm(text) is not None:
            self.say(message(text))
            return
        self.say(message(text), f"ALARM:{fault_alarm(text).value}")

    def _read_inputs(self) -> None:
        """The inputs active as the session starts; their changes follow as reports."""
        identity = self.machine.link.identity
        if identity is None or not identity.capabilities & INPUT_CAPABILITIES:
            return
        try:
            self.inputs_active = input_status(self.machine.link).active
        except LinkError:
            pass  # a board in trouble: its changes still come as reports

    def _on_report(self, report: Report) -> None:
        """The firmware's alarm (in the link's reader thread), told at once as GRBL does; an input's
        change kept for the reports."""
        if isinstance(report, InputChange):
            self.inputs_active = report.active
        if isinstance(report, Alarm) and report.code in FIRMWARE:
            self.alarm = self._board_alarm = True
            self.say(
                message(f"quadstep: firmware alarm {report.code.name}"),
                f"ALARM:{FIRMWARE[report.code].value}",
            )

    # --- lines -------------------------------------------------------------------------------

    def _work(self) -> None:
        answers: list[tuple[int, Answer]] = []  # lines read, not yet answered on the wire
        while True:
            if answers and (self._lines.empty() or len(answers) >= ANSWERS_HELD):
                self._answer_all(answers)
            entry = self._lines.get()
            if entry is None:
                return
            generation, line = entry
            if generation != self.executor.generation:
                continue  # sent before a soft reset
            if may_wait(line.text):
                self._answer_all(answers)
            answers.append((generation, self._answer(line, generation)))

    def _answer_all(self, answers: list[tuple[int, Answer]]) -> None:
        """The answers to the lines read so far, in one write (none to a line from before a soft
        reset); then the link's threads have their turn: a sender streams lines as fast as they are
        answered."""
        current = self.executor.generation
        lines = [text for generation, answer in answers if generation == current for text in answer]
        answers.clear()
        if lines:
            self.say(*lines)
        give_way()

    def _answer(self, line: Line, generation: int) -> Answer:
        if line.overflow:
            return [f"error:{GrblError.LINE_OVERFLOW.value}"]
        text = line.text.strip()
        if self.sleeping:
            return [f"error:{GrblError.GCODE_LOCK.value}"]
        try:
            if text.startswith("$"):
                return self._system(text, generation)
            return self._gcode(text, generation)
        except (JobError, MachineError, LinkError) as exc:
            return [message(str(exc)), f"error:{error_for(str(exc)).value}"]

    def _gcode(self, text: str, generation: int) -> Answer:
        if not text:
            return ["ok"]
        if self.alarm:
            return [f"error:{GrblError.GCODE_LOCK.value}"]
        with self._reader_lock:
            read = self.reader.read(text)
        items, probe = split_probe(read.items)
        if not self.check_mode and items:
            self.executor.submit(Work(items, read.coordinates, read.line), generation)
        if probe is not None and not self.check_mode:
            return self._probe(probe, generation)
        if read.ends_program:  # as GRBL: answered once the program's motion is done
            if not self.check_mode and not self.executor.wait_idle(generation):
                return []
            return [PGM_END, "ok"]
        return ["ok"]

    def _probe(self, move: ProbeMove, generation: int) -> Answer:
        """G38.x: at rest, the machine probes; the lines that follow go on from where it stopped."""
        if not self.executor.wait_idle(generation):
            return []
        self.probe_hold.start()
        self.probing = True
        try:
            outcome = run_probe(self.machine, move, self.last_probe, self.probe_hold)
        finally:
            self.probing = False
            with self._reader_lock:
                self.reader.resync(self.machine.position_mm)
        self.last_probe = outcome.report
        if outcome.alarm is None:
            return [outcome.report.line(), "ok"]
        self.alarm = True
        assert outcome.message is not None
        return [
            message(outcome.message),
            f"ALARM:{outcome.alarm.value}",
            outcome.report.line(),
            "ok",
        ]

    def _system(self, text: str, generation: int) -> Answer:
        command = text[1:].upper()
        if command.startswith("J="):
            return self._jog(text[3:], generation)
        answer = self._system_commands(generation).get(command)
        if answer is not None:
            return answer()
        try:
            write = parse_write(text)
            if write is not None:
                return self._write_setting(write)
        except SettingError as exc:
            return [message(str(exc)), f"error:{exc.error.value}"]
        if command.startswith(("N", "RST=")):
            return [NOT_KEPT, f"error:{GrblError.INVALID_STATEMENT.value}"]
        return [f"error:{GrblError.INVALID_STATEMENT.value}"]

    def _write_setting(self, write: SettingWrite) -> Answer:
        """At rest (GRBL's error 8 else): the setting into the file, used from the next line."""
        if not self.executor.idle or self.homing or self.probing:
            return [f"error:{GrblError.NOT_IDLE.value}"]
        if write.number == STATUS_MASK_SETTING:
            return self._write_status_mask(write)
        if write_setting(self.machine, self.options.config_path, write):
            with self._reader_lock:
                self.reader.reconfigure(self.machine.config, self.machine.position_mm)
        return ["ok"]

    def _write_status_mask(self, write: SettingWrite) -> Answer:
        """$10: what the reports carry, from the next one (this session's server keeps it)."""
        if write.value < 0:
            reason = f"$10={write.value:g}: a setting is never negative"
            return [message(reason), f"error:{GrblError.NEGATIVE_VALUE.value}"]
        if not write.value.is_integer() or write.value > 255:
            reason = f"$10={write.value:g}: the status report mask is a whole number 0 … 255"
            return [message(reason), f"error:{GrblError.INVALID_STATEMENT.value}"]
        self.status_mask.value = int(write.value)
        return ["ok"]

    def _system_commands(self, generation: int) -> dict[str, Callable[[], Answer]]:
        """`$` commands by name, each answering when called."""
        return {
            "": lambda: [HELP, "ok"],
            "$": lambda: [*settings_lines(self.machine.config, self.status_mask.value), "ok"],
            "I": lambda: [VERSION, OPTIONS, "ok"],
            "#": lambda: [
                *self._read(lambda: self.reader.offsets_report(self.last_probe.line())),
                "ok",
            ],
            "G": lambda: [*self._read(lambda: [self.reader.modal_report()]), "ok"],
            "N": lambda: ["$N0=", "$N1=", "ok"],
            "SLP": lambda: self._sleep(generation),
            "RST=#": lambda: self._clear_offsets(generation),
            "X": lambda: self._unlock(generation),
            "H": lambda: self._home(generation),
            "C": lambda: self._check_mode(generation),
        }

    def _read(self, report: Callable[[], list[str]]) -> list[str]:
        """A report of the modal state, taken while no line is being read."""
        with self._reader_lock:
            return report()

    def _jog(self, text: str, generation: int) -> Answer:
        """$J=: only when idle or jogging (GRBL's error 8 else, in an alarm too)."""
        if self.alarm or (not self.executor.idle and not self.executor.jogging):
            return [f"error:{GrblError.NOT_IDLE.value}"]
        try:
            with self._reader_lock:
                read = self.reader.jog(text)
        except JogError as exc:
            return [message(str(exc)), f"error:{GrblError.INVALID_JOG.value}"]
        self.executor.submit(Work(read.items, read.coordinates, read.line, jog=True), generation)
        return ["ok"]

    def _sleep(self, generation: int) -> Answer:
        """$SLP, as GRBL: at rest, the spindle (laser) and coolant off, then Sleep until a soft
        reset, which leaves an alarm ($X or $H unlocks)."""
        if not self.executor.wait_idle(generation):
            return []
        off = OutputState()
        with self._reader_lock:
            if self.reader.interpreter.outputs != off:
                self.machine.set_outputs(off)
                self.reader.interpreter.outputs = off
        self.sleeping = True
        return ["ok", SLEEPING]

    def _clear_offsets(self, generation: int) -> Answer:
        """$RST=#, as GRBL: at rest, G54–G59's offsets and the G28/G30 positions back to zero (G92
        and the tool length stay, as GRBL keeps neither with them)."""
        if not self.executor.wait_idle(generation):
            return []
        with self._reader_lock:
            kept = self.reader.coordinates
            cleared = WorkCoordinates(
                system=kept.system, g92=kept.g92, g92_applied=kept.g92_applied, tlo=kept.tlo
            )
            self.machine.adopt_coordinates(cleared)
            self.reader.reset_coordinates(cleared)
        return ["ok"]

    def _unlock(self, generation: int) -> Answer:
        if not self.executor.wait_idle(generation):
            return []
        if self.machine.status().state == State.ALARM:
            self.machine.emergency_stop()  # at rest already: a STOP clears the board's alarm
        self.alarm = self._board_alarm = False
        return ["[MSG:Caution: Unlocked]", "ok"]

    def _home(self, generation: int) -> Answer:
        if not any(a.homing is not None for a in self.machine.config.axes):
            return [f"error:{GrblError.HOMING_DISABLED.value}"]
        if not self.executor.wait_idle(generation):
            return []
        self.homing = True
        try:
            home(self.machine)
        except (MachineError, LinkError) as exc:
            self.alarm = True
            return [message(str(exc)), f"ALARM:{homing_alarm(str(exc)).value}", "ok"]
        finally:
            self.homing = False
        self.alarm = False
        with self._reader_lock:
            self.reader.resync(self.machine.position_mm)
        return ["ok"]

    def _check_mode(self, generation: int) -> Answer:
        if not self.executor.wait_idle(generation):
            return []
        self.check_mode = not self.check_mode
        if self.check_mode:
            return ["[MSG:Enabled]", "ok"]
        with (
            self._reader_lock
        ):  # leaving check mode resets the modal state, as GRBL's soft reset does
            self.reader.reset(self.machine.position_mm, self.machine.coordinates)
        return ["[MSG:Disabled]", "ok"]
