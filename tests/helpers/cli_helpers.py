"""The quadstep command as a process of its own, for tests that need its terminal, signals or stdin."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def cli_process(*args: str, stdin: int | None = None, env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    """`quadstep ARGS` in the repository, using this checkout's package, as the foreground process group of a
    terminal of its own would run it. Ctrl-C is given its usual meaning even when the tests run where SIGINT
    is ignored (a background job inherits that)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "host"), **(env or {}))
    launch = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); " \
             "from quadstep.cli import main; sys.exit(main())"
    return subprocess.Popen(
        [sys.executable, "-c", launch, *args],
        stdin=stdin, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO, env=env,
        start_new_session=True,
    )
