"""One sender's conversation: its bytes in, GRBL's answers out.

Realtime commands are handled in the receiving thread as they arrive; lines go to a worker thread
that answers each one, in order, once it is checked and queued (executor.py) or done (`$`
commands: system.py)."""

from __future__ import annotations

import queue
import re
import threading
from dataclasses import dataclass, field
from pathlib import Path

from ..give_way import give_way
from ..link import LinkError
from ..link.inputs import input_status
from ..machine import Machine, MachineError
from ..planner.program import JobError, ProbeMove
from ..protocol import Alarm, Capability, InputChange, Report
from .alarms import FIRMWARE, fault_alarm, firmware_alarm
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
    SOFT_RESET,
    STATUS,
    Line,
    Realtime,
    StreamSplitter,
)
from .reader import Reader
from .status import StatusBuilder, StatusMask
from .system import Answer, message, system_command

UNLOCK = "[MSG:'$H'|'$X' to unlock]"
# Lines a sender has in flight (a character-counting one: up to 128 bytes) are read and queued
# one by one, and their answers written together once no more have arrived (one write and one
# turn for the link's threads, not one per line), at most this many at once.
ANSWERS_HELD = 16
PROGRAM_END = re.compile(r"M0*(2|30)(?![\d.])")
PGM_END = "[MSG:Pgm End]"
INPUT_CAPABILITIES = Capability.LIMIT_INPUTS | Capability.PROBE_INPUT | Capability.CONTROL_INPUTS


def may_wait(text: str) -> bool:
    """A system command, a probe or a program end, which may wait for the machine: the lines before
    it are answered first, as they would be by then."""
    squeezed = "".join(text.split()).upper()
    return squeezed.startswith("$") or "G38" in squeezed or PROGRAM_END.search(squeezed) is not None


@dataclass(frozen=True)
class SessionOptions:
    """How `quadstep grbl` was started: M6 "ignore" (GRBL's default) or "pause" (held until `~`,
    as quadstep's tool change); the configuration file that settings writes go to (None: none);
    $10, which its sessions share (and the file keeps)."""

    tool_change: str = "ignore"
    config_path: Path | None = None
    status_mask: StatusMask = field(default_factory=StatusMask)

    @classmethod
    def of(
        cls, machine: Machine, tool_change: str = "ignore", config_path: Path | None = None
    ) -> SessionOptions:
        """$10 as the machine's configuration keeps it ([senders] status_mask)."""
        return cls(tool_change, config_path, StatusMask(machine.config.senders.status_mask))


class Session:
    """GRBL 1.1 on `machine` for one client, whose answers go out through `port`."""

    def __init__(
        self,
        machine: Machine,
        port: SenderPort,
        options: SessionOptions | None = None,
    ) -> None:
        self.machine = machine
        self.options = options = options if options is not None else SessionOptions.of(machine)
        self._outbox = Outbox(port)
        self.reader_lock = threading.Lock()
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
        self.board_alarm = False  # the firmware raised an alarm; $X clears it
        self.status_mask = options.status_mask
        self.config_path = options.config_path  # where settings writes go
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
            with self.reader_lock:
                self.reader.resync(self.machine.position_mm)

    def _toggle_coolant(self, byte: int) -> None:
        """0xA0 flood, 0xA1 mist: switched now at rest (and kept in the modal state, as M8/M7 and
        M9 would); ignored while anything moves or the firmware has no outputs."""
        if not self.executor.idle or self.homing or self.probing or self.check_mode:
            return
        with self.reader_lock:
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
        with self.reader_lock:
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
        if self.board_alarm and firmware_alarm(text) is not None:
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
            self.alarm = self.board_alarm = True
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
                return system_command(self, text, generation)
            return self._gcode(text, generation)
        except (JobError, MachineError, LinkError) as exc:
            return [message(str(exc)), f"error:{error_for(str(exc)).value}"]

    def _gcode(self, text: str, generation: int) -> Answer:
        if not text:
            return ["ok"]
        if self.alarm:
            return [f"error:{GrblError.GCODE_LOCK.value}"]
        with self.reader_lock:
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
            with self.reader_lock:
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
