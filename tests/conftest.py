"""Fixtures shared by the Python tests: the emulator binary (built once) and running instances, a small
machine for the jog, machine and TUI tests, and a state folder of each test's own.

The test folders mirror the package (tests/protocol for host/quadstep/protocol, ...); helpers shared
between them are in tests/helpers (on the path, pyproject.toml)."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from hypothesis import settings

from quadstep.config import MachineConfig, parse_config
from quadstep.emulator import EMULATOR_ENV, Emulator
from quadstep.link import Link
from tui_helpers import MACHINE

REPO = Path(__file__).resolve().parents[1]

# Property tests draw the same examples on every run (a suite that passes passes again, on any
# machine); HYPOTHESIS_PROFILE=explore draws new ones each run, to look for what those miss.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore")
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))
# A test that asks for one of these, or lives in tests/simavr, starts an emulator or simavr.
PROCESS_FIXTURES = frozenset({"emulator_binary", "avr_build"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark `emulator` every test that starts a board process, so `-m 'not emulator'` runs the others."""
    for item in items:
        fixtures = set(getattr(item, "fixturenames", ()))
        if fixtures & PROCESS_FIXTURES or item.path.is_relative_to(REPO / "tests" / "simavr"):
            item.add_marker(pytest.mark.emulator)


def pytest_terminal_summary(terminalreporter) -> None:
    """Why each test run again (make test's --reruns) failed its first run: a starved board on a busy
    machine, or a fault to look into."""
    for report in terminalreporter.stats.get("rerun", []):
        crash = getattr(report.longrepr, "reprcrash", None)
        why = crash.message if crash is not None else str(report.longrepr)
        terminalreporter.write_line(f"first run of {report.nodeid} failed: {why[:2000]}")


@pytest.fixture(autouse=True)
def state_home(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Every test keeps work coordinates in a state folder of its own, never in the user's."""
    home = tmp_path_factory.mktemp("state")
    monkeypatch.setenv("XDG_STATE_HOME", str(home))
    return home


@pytest.fixture(scope="session")
def emulator_binary() -> Path:
    """The emulator, built with `make emulator` once per session (a no-op when up to date)."""
    if os.environ.get(EMULATOR_ENV):
        return Path(os.environ[EMULATOR_ENV])
    result = subprocess.run(["make", "-C", str(REPO), "-s", "emulator"], capture_output=True, text=True)
    if result.returncode != 0:
        pytest.fail(f"`make emulator` failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return REPO / "build" / "native" / "quadstep-emu"


StartEmulator = Callable[..., Emulator]


@pytest.fixture
def start_emulator(emulator_binary: Path) -> Iterator[StartEmulator]:
    """start_emulator(**Emulator options) -> a running Emulator, stopped after the test."""
    started: list[Emulator] = []

    def start(**options: object) -> Emulator:
        emu = Emulator(binary=emulator_binary, **options).start()  # type: ignore[arg-type]
        started.append(emu)
        return emu

    yield start
    for emu in started:
        emu.stop()


@pytest.fixture
def free_emulator(start_emulator: StartEmulator, tmp_path: Path) -> Emulator:
    """A free-running 4-axis emulator writing its step trace to tmp_path/trace.csv."""
    return start_emulator(free=True, trace=tmp_path / "trace.csv")


@pytest.fixture
def free_link(free_emulator: Emulator) -> Iterator[Link]:
    with Link.open(free_emulator.url) as link:
        yield link


@pytest.fixture
def machine() -> MachineConfig:
    return parse_config(MACHINE, "test machine")


@pytest.fixture
def paced_emulator(start_emulator, tmp_path: Path) -> Emulator:
    """3 axes in real time (50 kHz), as a board would run; step trace in tmp_path/trace.csv."""
    return start_emulator(free=False, axes=3, trace=tmp_path / "trace.csv")


@pytest.fixture
def paced_link(paced_emulator: Emulator) -> Iterator[Link]:
    with Link.open(paced_emulator.url) as link:
        yield link


@pytest.fixture
def fast_link(start_emulator) -> Iterator[Link]:
    """3 axes, free-running: incremental jogs finish at once."""
    emu = start_emulator(free=True, axes=3)
    with Link.open(emu.url) as link:
        yield link
