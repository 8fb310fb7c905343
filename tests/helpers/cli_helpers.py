"""The quadstep command as a process of its own, for tests that need its terminal, signals or stdin."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def cli_process(*args: str, stdin: int | None = None, env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    """`quadstep ARGS` in the repository, using this checkout's package, as the foreground process group of a
    terminal of its own would run it. Ctrl-C and SIGHUP are given their usual meanings even when the tests
    run where they are ignored (a background job inherits an ignored SIGINT, a run under nohup an ignored
    SIGHUP)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "host"), **(env or {}))
    launch = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); " \
             "signal.signal(signal.SIGHUP, signal.SIG_DFL); " \
             "from quadstep.cli import main; sys.exit(main())"
    return subprocess.Popen(
        [sys.executable, "-c", launch, *args],
        stdin=stdin, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO, env=env,
        start_new_session=True,
    )


def child_pids(pid: int) -> list[int]:
    """The processes `pid` started, whichever of its threads started them."""
    pids = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            pids += [int(p) for p in (task / "children").read_text().split()]
        except OSError:
            pass  # the thread ended meanwhile
    return pids


def wait_for_child(process: subprocess.Popen[str], timeout: float = 60.0) -> int:
    """Until the command has started a process of its own (the emulator), however loaded the machine; its pid."""
    deadline = time.monotonic() + timeout
    while not (children := child_pids(process.pid)):
        assert process.poll() is None and time.monotonic() < deadline, "the command started no emulator"
        time.sleep(0.05)
    return children[0]
