"""One machine state across commands: `home`, `probe`, `backlash measure` and `run` as separate
processes on one board (an emulator kept running, serving TCP, with a simulated machine that has
backlash) move the carriages step for step as the same sequence in one Machine does; a board reset
between two commands is named and its band and homing are not reused; a second process on the same
machine is refused."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cli_helpers import REPO, cli_process
from machine_helpers import read_trace_with_carriage
from quadstep.config import load_config
from quadstep.emulator import Emulator
from quadstep.job import load_job
from quadstep.machine import Machine, Target, open_machine, state_path
from quadstep.machine.backlash import PROBE_SETUP, measure_with_probe
from quadstep.machine.homing import home
from quadstep.machine.carry_over import RESET_NOTICE
from quadstep.machine.probing import probe
from quadstep.machine.state import read_state
from quadstep.machine.state_lock import MachineBusy, StateLock

BACKLASH = (55, 18, 89)  # steps, the simulated machine's and the configuration's
TIMEOUT = 300.0  # s for any one command

CONFIG = """\
tick_hz = 32000
homing_required = true
[inputs]
hard_limits = true
debounce_ms = 0.5
""" + "".join(f"""
[[axes]]
name = "{name}"
steps_per_mm = 400
max_speed = {speed}
max_accel = {accel}
travel_min = {low}
travel_max = {high}
[axes.backlash]
mm = {steps / 400}
[axes.homing]
end = "{end}"
seek = {seek}
locate = 1
pull_off = 1
""" for name, speed, accel, low, high, end, seek, steps in (
    ("X", 40, 500, 0, 300, "min", 20, BACKLASH[0]), ("Y", 40, 500, 0, 200, "min", 20, BACKLASH[1]),
    ("Z", 15, 200, -60, 0, "max", 10, BACKLASH[2])))

# Switches 1 mm beyond the travel's ends, where homing puts them (switch_at's default: pull_off
# beyond), so that this board's steps are machine steps; a touch plate 10 mm below the top of Z
# everywhere; a block whose -X, -Y corner is at (10, 10) mm, its top 2.5 mm below the top of Z, to
# measure X's backlash at.
SIM = f"""\
seed = 1
[[axis]]
start = 2000
backlash = {BACKLASH[0]}
hard_min = -800
hard_max = 120400
[axis.limit_min]
at = -400.0
hysteresis = 8
bounce = 2
bounce_ticks = 40
[[axis]]
start = 2400
backlash = {BACKLASH[1]}
hard_min = -800
hard_max = 80400
[axis.limit_min]
at = -400.0
hysteresis = 8
bounce = 2
bounce_ticks = 40
[[axis]]
start = -2000
backlash = {BACKLASH[2]}
hard_min = -24400
hard_max = 800
[axis.limit_max]
at = 400.0
hysteresis = 8
[probe]
hysteresis = 1.5
[[probe.target]]
kind = "plate"
z = -4000.5
[[probe.target]]
kind = "block"
x_min = 4000
x_max = 8000
y_min = 4000
y_max = 8000
z = -1000
"""

# 0.5 mm outside the block's -X face, 1 mm inside its -Y face's edge
TO_THE_BLOCK = "G21 G90\nG0 Z-5\nG0 X9.5 Y11\n"
CUT = """\
G21 G90
G10 L20 P1 X0 Y0 Z0
G0 Z2
G1 X-5 Y-3 F900
G1 X-2 Y-6
G1 X-4 Y-2 Z1
G1 X-1 Y-1 Z1.5
"""
PROBE_Z = -15.0  # mm: down onto the plate


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    names = {"config": ("router.toml", CONFIG), "sim": ("sim.toml", SIM),
             "to_block": ("to_block.gcode", TO_THE_BLOCK), "cut": ("cut.gcode", CUT)}
    for name, text in names.values():
        (tmp_path / name).write_text(text)
    return {key: tmp_path / name for key, (name, _) in names.items()}


def board(start_emulator: Callable[..., Emulator], sim: Path, trace: Path | None = None,
          free: bool = True) -> Emulator:
    """An emulator with the simulated machine, serving TCP, kept running across commands."""
    return start_emulator(free=free, tick_hz=32_000, axes=3, trace=trace,
                          extra_args=["--machine", str(sim), "--tcp", "0"])


def command(*args: str, cwd: Path, env: dict[str, str] | None = None
            ) -> subprocess.CompletedProcess[str]:
    """`quadstep ARGS` as a process of its own (this checkout's package, the test's state folder,
    or the environment `env` adds)."""
    env = dict(os.environ, PYTHONPATH=str(REPO / "host"), **(env or {}))
    return subprocess.run([sys.executable, "-m", "quadstep.cli", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=TIMEOUT)


def json_of(result: subprocess.CompletedProcess[str]) -> Any:
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def plain(value: Any) -> Any:
    """As JSON has it (tuples become lists)."""
    return json.loads(json.dumps(value))


def run_in(machine: Machine, path: Path) -> dict[str, Any]:
    """A job as `quadstep run` runs it, and what its --json says of where it ends."""
    job = load_job(path, machine.config, machine.position, False, machine.coordinates)
    end = machine.run_job(job.plan, job.program, job.label).wait(TIMEOUT)
    assert end is not None and end.ended_by == "done"
    machine.adopt_coordinates(job.end_coordinates)
    return {"positions_steps": list(machine.position),
            "positions_work_mm": list(machine.work_position),
            "work_system": machine.coordinates.name}


def in_one_machine(machine: Machine, files: dict[str, Path]) -> list[Any]:
    """The sequence in one Machine, each step's result as the command prints it with --json."""
    results: list[Any] = []
    homed = home(machine)
    results.append({"axes": [r.__dict__ for r in homed], "position_mm": list(machine.position_mm)})
    target = list(machine.position_mm)
    target[2] = PROBE_Z
    results.append(probe(machine, "38.2", target, 1.0).__dict__)
    results.append(run_in(machine, files["to_block"]))
    toward, test = PROBE_SETUP["X"]
    measured = measure_with_probe(machine, "X", toward=toward, test=test, test_toward=1,
                                  tries=2, search=10.0, clear=3.0, largest=1.0, feed=2.0,
                                  max_spread=0.01)
    results.append(measured.as_dict())
    results.append(run_in(machine, files["cut"]))
    return plain(results)


def as_commands(url: str, files: dict[str, Path], cwd: Path) -> list[Any]:
    """The same sequence as separate commands."""
    where = ["--config", str(files["config"]), "--port", url, "--json"]
    keep = ("positions_steps", "positions_work_mm", "work_system")
    results = [json_of(command("home", *where, cwd=cwd)),
               json_of(command("probe", f"Z={PROBE_Z}", *where, cwd=cwd))]
    ran = json_of(command("run", str(files["to_block"]), *where, cwd=cwd))
    assert ran["completed"] and ran["exact"]
    results.append({key: ran[key] for key in keep})
    results.append(json_of(command("backlash", "measure", "--axis", "X", "--tries", "2", *where,
                                   cwd=cwd)))  # the other settings: as in in_one_machine
    ran = json_of(command("run", str(files["cut"]), *where, cwd=cwd))
    assert ran["completed"] and ran["exact"]
    results.append({key: ran[key] for key in keep})
    return results


def carriages(summary: dict[str, Any]) -> list[float]:
    return [axis["carriage"] for axis in summary["machine"]["axes"]]


def test_separate_commands_move_the_carriages_as_one_machine_does(
        start_emulator: Callable[..., Emulator], files: dict[str, Path], tmp_path: Path) -> None:
    config = load_config(files["config"])
    together = board(start_emulator, files["sim"], tmp_path / "together.csv")
    with open_machine(Target(port=together.url), config) as machine:
        expected = in_one_machine(machine, files)
    apart = board(start_emulator, files["sim"], tmp_path / "apart.csv")
    printed = as_commands(apart.url, files, tmp_path)
    assert printed == expected  # homing, the probe's contact, the backlash, where each job ends
    final = carriages(apart.stop())
    assert final == carriages(together.stop())
    one = read_trace_with_carriage(tmp_path / "together.csv")
    many = read_trace_with_carriage(tmp_path / "apart.csv")
    # every step: tick, axis, direction, motor, carriage
    assert len(many) > 10_000 and np.array_equal(many, one)
    # the cut ends at its last target in the work zero it set, and the carriage is there (the board
    # counts machine steps: the simulated carriage within a step of the position shown)
    assert printed[4]["positions_work_mm"] == pytest.approx([-1.0, -1.0, 1.5])
    assert np.abs(np.array(final) - np.array(printed[4]["positions_steps"])).max() <= 1.0, final


def test_a_board_reset_between_commands_is_named_and_its_band_and_homing_not_reused(
        start_emulator: Callable[..., Emulator], files: dict[str, Path], tmp_path: Path) -> None:
    where = ["--config", str(files["config"])]
    first = board(start_emulator, files["sim"])
    assert command("home", *where, "--port", first.url, cwd=tmp_path).returncode == 0
    ran = command("run", str(files["to_block"]), *where, "--port", first.url, cwd=tmp_path)
    assert ran.returncode == 0, ran.stderr  # homed: kept from the command before
    coordinates = read_state(state_path(files["config"])).coordinates
    kept = read_state(state_path(files["config"]))
    assert kept.homed and kept.band is not None and None not in kept.band.w
    first.stop()
    second = board(start_emulator, files["sim"], tmp_path / "trace.csv")  # the board restarted
    refused = command("run", str(files["to_block"]), *where, "--port", second.url, cwd=tmp_path)
    assert refused.returncode == 1
    assert RESET_NOTICE == ("the board was reset since the last command: its position is lost; "
                            "home it")
    assert RESET_NOTICE in refused.stderr
    assert "home the machine first" in refused.stderr
    after = read_state(state_path(files["config"]))
    assert not after.homed and after.band is not None and after.band.w == [None, None, None]
    assert after.coordinates == coordinates  # relative to machine zero, which homing finds again
    summary = second.stop()
    assert all(axis["pulses"] == 0 for axis in summary["machine"]["axes"])  # nothing moved


def test_a_second_process_on_the_machine_is_refused_until_the_first_ends(
        start_emulator: Callable[..., Emulator], files: dict[str, Path], tmp_path: Path) -> None:
    long_job = tmp_path / "long.gcode"
    long_job.write_text("G21 G90\nG1 X60 F600\n")  # 6 s on a board in real time
    no_homing = tmp_path / "router.toml"
    no_homing.write_text(CONFIG.replace("homing_required = true\n", ""))
    emu = board(start_emulator, files["sim"], free=False)
    first = cli_process("run", str(long_job), "--config", str(no_homing), "--port", emu.url)
    try:
        assert first.stdout is not None
        assert "planned" in first.stdout.readline()  # connected, streaming
        second = command("home", "--config", str(no_homing), "--port", emu.url, cwd=tmp_path)
        assert second.returncode == 1
        assert second.stderr.strip() == (
            f"quadstep home: error: another quadstep (pid {first.pid}) holds this machine "
            f"({no_homing}); close it first")
        first.send_signal(signal.SIGINT)  # the user's stop: a HOLD; the lock goes with the process
        assert first.wait(TIMEOUT) == 130
    finally:
        if first.poll() is None:
            first.kill()
            first.wait(TIMEOUT)
    config = load_config(no_homing)
    with open_machine(Target(port=emu.url), config, state_file=state_path(no_homing)) as machine:
        assert machine.state_lock is not None  # taken again at once


def test_a_crashed_holder_leaves_the_machine_free(tmp_path: Path) -> None:
    state = tmp_path / "machine.json"
    hold = ("import sys; from pathlib import Path; "
            "from quadstep.machine.state_lock import StateLock; "
            f"lock = StateLock.acquire(Path({str(state)!r}), 'm'); print('held', flush=True); "
            "sys.stdin.read()")
    holder = subprocess.Popen([sys.executable, "-c", hold], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True,
                              env=dict(os.environ, PYTHONPATH=str(REPO / "host")))
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        with pytest.raises(MachineBusy, match=rf"another quadstep \(pid {holder.pid}\) holds"):
            StateLock.acquire(state, "m")
        holder.kill()  # no release: the kernel lets go of the lock with the process
        holder.wait(TIMEOUT)
        StateLock.acquire(state, "m").release()
    finally:
        if holder.poll() is None:
            holder.kill()
            holder.wait(TIMEOUT)


def test_a_state_folder_that_cannot_be_written_is_one_line_before_anything_moves(
        start_emulator: Callable[..., Emulator], files: dict[str, Path], tmp_path: Path) -> None:
    not_a_folder = tmp_path / "state-file"
    not_a_folder.write_text("")
    emu = board(start_emulator, files["sim"])
    result = command("run", str(files["cut"]), "--config", str(files["config"]), "--port", emu.url,
                     cwd=tmp_path, env={"XDG_STATE_HOME": str(not_a_folder)})
    assert result.returncode == 1
    assert result.stderr.strip() == (
        f"quadstep run: error: cannot keep the machine's state in {not_a_folder}/quadstep: Not a "
        "directory; make it writable or set XDG_STATE_HOME to a folder that is")
    assert all(axis["pulses"] == 0 for axis in emu.stop()["machine"]["axes"])
