"""A host that falls behind: the board runs dry, brakes to rest and waits (STARVED, no alarm), and the job plans
what is left from there and goes on by itself, ending exactly on every target."""

from __future__ import annotations

import json
import os
import signal
import threading
import time
from pathlib import Path

import pytest
from cli_helpers import cli_process
from fault_jobs import engraving

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.link.outbox import SILENCE
from quadstep.machine import JobState, Machine
from quadstep.protocol import Alarm

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)


def test_a_job_whose_host_stalls_goes_on_after_the_board_ran_dry(start_emulator, tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "engraving.gcode"
    path.write_text(engraving(150))
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14)  # real time, an Uno's queue
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        job = load_job(path, CONFIG, machine.position)
        stalled = threading.Event()
        send = link.send

        def falls_behind(message, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003
            if not stalled.is_set() and link.segments_done > 40:
                stalled.set()
                time.sleep(0.8)  # the host busy elsewhere: the 14 slots hold less than that
            return send(message, *args, **kwargs)

        monkeypatch.setattr(link, "send", falls_behind)  # the stream thread stalls once, mid-job
        run = machine.run_job(job.plan, job.program)
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert stalled.is_set() and run.progress.starvations >= 1
        history = run.states.history
        at = history.index(JobState.STARVED)
        assert history[at:at + 3] == [JobState.STARVED, JobState.RESUMING, JobState.STREAMING]
        assert history[-1] is JobState.DONE
        assert machine.position == job.plan.end
        assert machine.report_count(Alarm) == 0  # never an alarm


def test_quadstep_run_goes_on_through_stalls_of_the_host(start_emulator, tmp_path: Path) -> None:
    path = tmp_path / "engraving.gcode"
    path.write_text(engraving(300))
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    process = cli_process("run", str(path), "--config", str(ROUTER), "--port", emu.url, "--json")
    assert process.stdout is not None
    for _ in range(3):  # frozen three times for 0.7 s, as a loaded small computer may be
        time.sleep(1.0)
        os.kill(process.pid, signal.SIGSTOP)
        time.sleep(0.7)
        os.kill(process.pid, signal.SIGCONT)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    result = json.loads(out.splitlines()[-1])
    assert result["completed"] and result["exact"], result
    assert result["starvations"] >= 1
    assert "starved, going on" in err
    assert tuple(result["positions_steps"]) == load_job(path, CONFIG).plan.end




def test_quadstep_run_goes_on_after_a_freeze_longer_than_the_links_silence_limit(start_emulator,
                                                                                  tmp_path: Path) -> None:
    """Frozen for 3 s, twice the link's silence limit (a laptop's lid, a small computer swapping): the board ran
    dry meanwhile and said so, and the host reads that on waking instead of taking its own pause for a silent
    board."""
    path = tmp_path / "engraving.gcode"
    path.write_text(engraving(300))
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    process = cli_process("run", str(path), "--config", str(ROUTER), "--port", emu.url)
    assert process.stdout is not None
    assert "planned" in process.stdout.readline()  # printed as the stream starts
    time.sleep(1.0)
    os.kill(process.pid, signal.SIGSTOP)
    time.sleep(2 * SILENCE)
    os.kill(process.pid, signal.SIGCONT)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert "has not answered" not in err and "starved, going on" in err
    assert out.splitlines()[0].startswith("done: ")
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    with Link.open(emu.url) as link:
        assert tuple(link.status().position[:3]) == load_job(path, CONFIG).plan.end
