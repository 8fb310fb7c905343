"""What is read as a configuration, a job or the state file must be a regular file of bounded
size, its JSON and YAML without a key given twice and without nesting the parser cannot follow:
anything else is one error line naming the file, and nothing is read without end."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from quadstep.cli import main
from quadstep.config import ConfigError, load_config
from quadstep.machine.state import StateError, read_state
from quadstep.movefile import read_move_file
from quadstep.planner.program import JobError
from quadstep.textfile import SETTINGS_MAX_BYTES, read_text

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
DEMO = REPO / "examples" / "demo.gcode"


def _error_line(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(args) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_a_device_as_configuration_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    line = _error_line(["check", str(DEMO), "--config", "/dev/zero"], capsys)
    assert line == ("quadstep check: error: /dev/zero: a character device, not a regular file: "
                    "quadstep reads configurations and jobs from files")


@pytest.mark.parametrize("role", ["config", "job"])
def test_a_link_to_a_device_is_refused(role: str, tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    link = tmp_path / ("machine.toml" if role == "config" else "job.gcode")
    link.symlink_to("/dev/zero")
    args = ["check", str(DEMO), "--config", str(link)] if role == "config" else \
        ["check", str(link), "--config", str(ROUTER)]
    assert f"{link}: a character device, not a regular file" in _error_line(args, capsys)


def test_a_state_file_linked_to_a_device_is_refused(tmp_path: Path) -> None:
    link = tmp_path / "state.json"
    link.symlink_to("/dev/zero")
    with pytest.raises(StateError, match="a character device, not a regular file"):
        read_state(link)


def test_a_pipe_is_refused_without_waiting_for_a_writer(tmp_path: Path) -> None:
    pipe = tmp_path / "job.gcode"
    os.mkfifo(pipe)
    with pytest.raises(JobError, match=f"^{pipe}: a pipe, not a regular file"):
        read_text(pipe, JobError)


def test_a_directory_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="a directory, not a regular file"):
        load_config(tmp_path)


def test_a_configuration_larger_than_a_few_megabytes_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "big.toml"
    path.write_text(ROUTER.read_text() + "#" * SETTINGS_MAX_BYTES + "\n")
    with pytest.raises(ConfigError, match=r"big.toml: 4 MB, larger than the 4 MB such a file may"):
        load_config(path)
    load_config(ROUTER)  # the example is far below


def test_a_job_may_be_larger_than_a_configuration(tmp_path: Path) -> None:
    path = tmp_path / "job.gcode"
    path.write_text("G0 X1\n" + "(comment)\n" * (SETTINGS_MAX_BYTES // 10 + 1))
    assert len(read_text(path, JobError)) > SETTINGS_MAX_BYTES


def test_a_key_twice_in_a_move_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "moves.json"
    path.write_text('{"moves": [{"to": {"X": 10}, "feed": 10}], "moves": [{"dwell": 1}]}')
    with pytest.raises(JobError, match=r"moves.json: key 'moves' is given twice in one"):
        read_move_file(path)
    path = tmp_path / "moves.yaml"
    path.write_text("moves:\n  - to: {X: 10, X: 20}\n    feed: 10\n")
    with pytest.raises(JobError, match=r"moves.yaml: line 2: key 'X' is given twice in one"):
        read_move_file(path)


def test_a_key_twice_in_the_state_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "state.json"
    path.write_text('{"coordinates": {}, "coordinates": {}}')
    with pytest.raises(StateError, match=r"state.json: key 'coordinates' is given twice"):
        read_state(path)


def test_a_key_twice_in_a_raw_segment_file_is_refused(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "segments.json"
    segment = json.dumps({"n": 10, "axes": []}).replace('"n": 10', '"n": 10, "n": 20')
    path.write_text('{"segments": [' + segment + "]}")
    line = _error_line(["send", str(path), "--port", "/dev/nonexistent-board"], capsys)
    assert line == (f"quadstep send: error: {path}: key 'n' is given twice in one object "
                    "(which one is meant?)")


def test_a_key_twice_in_a_configuration_is_refused(tmp_path: Path) -> None:
    """TOML's own rule; checked here so that it stays so."""
    path = tmp_path / "twice.toml"
    text = ROUTER.read_text().replace("tick_hz = 32000", "tick_hz = 32000\ntick_hz = 50000")
    path.write_text(text)
    with pytest.raises(ConfigError, match="twice.toml: not valid TOML"):
        load_config(path)


@pytest.mark.parametrize("reader", ["state", "moves"])
def test_json_nested_a_hundred_thousand_deep_is_refused(reader: str, tmp_path: Path) -> None:
    path = tmp_path / f"{reader}.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    error = StateError if reader == "state" else JobError
    with pytest.raises(error, match="nested too deep"):
        read_state(path) if reader == "state" else read_move_file(path)
