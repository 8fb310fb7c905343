"""The state file: where it is, what it holds, and that a crash never leaves half of it."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from quadstep.coordinates import WorkCoordinates
from quadstep.machine import StateError, load_state, save_state, state_path


def test_one_file_per_configuration_under_xdg_state_home(state_home: Path, tmp_path: Path) -> None:
    a, b = tmp_path / "a" / "router.toml", tmp_path / "b" / "router.toml"
    assert state_path(None) == state_home / "quadstep" / "default.json"
    assert state_path(a).parent == state_home / "quadstep" and state_path(a).name.startswith("router-")
    assert state_path(a) != state_path(b)  # same name, other folder: another machine
    assert state_path(a) == state_path(tmp_path / "a" / ".." / "a" / "router.toml")


def test_no_file_yet_is_g54_with_every_offset_zero(tmp_path: Path) -> None:
    coords = load_state(tmp_path / "none.json")
    assert coords == WorkCoordinates() and coords.name == "G54" and coords.offset("X") == 0.0


def test_what_is_saved_is_read_back(tmp_path: Path) -> None:
    coords = WorkCoordinates()
    coords.set_offset(3, "Z", -12.5)
    coords.system = 3
    coords.set_g92("X", 4.0, 1.0)
    coords.store(28, ("X", "Y"), (1.0, 2.0))
    path = tmp_path / "deep" / "state.json"
    save_state(path, coords)
    assert load_state(path) == coords
    assert json.loads(path.read_text())["version"] == 2
    assert [p.name for p in path.parent.iterdir()] == ["state.json"]  # no temporary file left


def test_a_version_1_file_is_read_and_rewritten_as_version_2(tmp_path: Path) -> None:
    path = tmp_path / "state.json"
    path.write_text('{"version": 1, "coordinates": {"system": 2}}')
    assert load_state(path).name == "G55"
    coords = load_state(path)
    coords.set_offset(2, "X", 1.5)
    save_state(path, coords)
    assert json.loads(path.read_text())["version"] == 2 and load_state(path) == coords


def test_a_crash_while_saving_leaves_the_old_file_whole(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "state.json"
    old = WorkCoordinates()
    old.set_offset(1, "X", 5.0)
    save_state(path, old)
    before = path.read_bytes()

    def crash(fd: int) -> None:
        raise OSError("disk gone")

    monkeypatch.setattr(os, "fsync", crash)
    new = WorkCoordinates()
    new.set_offset(1, "X", 99.0)
    with pytest.raises(OSError, match="disk gone"):
        save_state(path, new)
    assert path.read_bytes() == before and load_state(path) == old
    assert [p.name for p in tmp_path.iterdir()] == ["state.json"]


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("{", "not valid JSON"),
        ('{"version": 1, "coordinates": {"system": 7}}', "coordinates.system = 7: must be at most 6"),
        ('{"version": 3}', "version = 3: must be one of"),
    ],
)
def test_a_bad_file_is_an_error_naming_it(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "state.json"
    path.write_text(content)
    with pytest.raises(StateError) as caught:
        load_state(path)
    assert str(caught.value).startswith(f"{path}: ") and message in str(caught.value)
