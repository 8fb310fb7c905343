"""bCNC's own sender, headless: `python3 bcnc_stream.py URL JOB [PROBE_LINE…]` opens URL (a serial
path or socket://HOST:PORT) with bCNC's Sender and its GRBL1 controller, loads JOB with bCNC's G-code
reader, compiles it into the Sender's queue and lets bCNC's serial thread stream it (bCNC's
character counting against GRBL's 128-byte buffer), as bCNC's Run does without its window; then
sends each PROBE_LINE and waits for bCNC to read the probe's result. Prints one JSON object: the
lines bCNC counted and expected, its errors, the state and the machine and work positions it last
read, and the probe positions it read. bCNC's Sender needs no display (its window does)."""

from __future__ import annotations

import builtins
import json
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

TIMEOUT = 120.0


def bcnc_path() -> Path:
    import importlib.util

    spec = importlib.util.find_spec("bCNC")
    if spec is None or spec.origin is None:
        raise SystemExit("bCNC is not installed (pip install bCNC)")
    return Path(spec.origin).parent


def wait(predicate: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + TIMEOUT
    while not predicate():
        if time.monotonic() > deadline:
            raise SystemExit(f"timed out waiting for {what}")
        time.sleep(0.05)


def main(url: str, job: str, probes: list[str]) -> dict[str, object]:
    base = bcnc_path()
    for sub in ("", "lib", "plugins", "controllers"):
        sys.path.append(str(base / sub))
    setattr(builtins, "_", lambda text: text)  # bCNC's gettext, untranslated
    import Utils  # noqa: E402  (bCNC's modules, found on the paths above)

    Utils.loadConfiguration(systemOnly=True)  # bCNC's defaults, not the user's ~/.bCNC
    from CNC import CNC, WAIT  # noqa: E402
    from Sender import Sender  # noqa: E402

    class Headless(Sender):  # the window's hooks that Sender calls
        def disable(self) -> None:
            pass

        def enable(self) -> None:
            pass

    sender = Headless()
    sender.controllerSet("GRBL1")
    sender.open(url, 115200)
    wait(lambda: CNC.vars["state"] == "Idle", "Idle after connecting")
    errors: list[str] = []
    try:
        sender.load(job)
        sender.initRun()
        sender._gcount = 0
        paths = sender.gcode.compile(sender.queue, lambda: False)
        sender._runLines = len(paths) + 1
        sender.queue.put((WAIT,))
        wait(lambda: sender._gcount >= sender._runLines, "the job's lines")
        counted, expected = sender._gcount, sender._runLines
        sender.runEnded()
        wait(lambda: CNC.vars["state"] == "Idle", "Idle after the job")
        sender._posUpdate = False
        wait(lambda: sender._posUpdate, "a status report after the end")
        machine = [CNC.vars["mx"], CNC.vars["my"], CNC.vars["mz"]]
        work = [CNC.vars["wx"], CNC.vars["wy"], CNC.vars["wz"]]
        probed = []
        for line in probes:
            if line.upper().startswith("G38"):
                # bCNC asks `$#` itself after offsets change, and a [PRB:] line of its answer may
                # still be on the way: one `$#` more, answered in line order (its [PRB:] last),
                # flushes it; then the next [PRB:] is the probe's
                CNC.vars["PRB"] = None
                sender.sendGCode("$#")
                wait(lambda: CNC.vars["PRB"] is not None, "the answer to $#")
                CNC.vars["PRB"] = None
                sender.sendGCode(line)
                wait(lambda: CNC.vars["PRB"] is not None, f"the result of {line}")
                probed.append([CNC.vars["prbx"], CNC.vars["prby"], CNC.vars["prbz"]])
            else:
                sender.sendGCode(line)
        while not sender.log.empty():
            kind, text = sender.log.get()
            if kind == Sender.MSG_ERROR:
                errors.append(str(text))
    finally:
        thread, sender.thread = sender.thread, None  # ends bCNC's serial thread
        if thread is not None:
            thread.join(timeout=5)
        sender.serial.close()
    return {
        "counted": counted,
        "expected": expected,
        "errors": errors,
        "state": CNC.vars["state"],
        "machine": machine,
        "work": work,
        "probed": probed,
    }


if __name__ == "__main__":
    result = main(sys.argv[1], sys.argv[2], sys.argv[3:])
    sys.stdout.flush()
    os.write(1, ("\nRESULT " + json.dumps(result) + "\n").encode())
