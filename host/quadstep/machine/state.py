"""The state file: what the host knows of one machine beyond the board's step counts, kept across
commands.

That is the work coordinates, where each carriage sits in its backlash (the band), whether the
machine is homed (or lost its position to a hard limit or the abort button), and the board it all
belongs to: its boot id where the firmware reports one, its motion clock and step counts when the
file was written (board_identity.py tells a board reset since then; carry_over.py what is kept).

One file per machine configuration, at

    $XDG_STATE_HOME/quadstep/<config name>-<8 hex digits>.json   (XDG_STATE_HOME defaults to
    ~/.local/state)

where the digits come from the configuration file's absolute path (two files
of one name in different folders are two machines), and `default.json` for
the generic configuration. It is replaced whole and atomically (written
beside it, flushed to disk, renamed over it), so a crash leaves the old file
or the new one, never half of either. A lock file beside it (state_lock.py) lets
one process at a time hold the machine.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Final, Literal

from pydantic import BaseModel, ConfigDict

from ..backlash.band import BandRecord
from ..coordinates import WorkCoordinates
from ..textfile import SETTINGS_MAX_BYTES, parse_nested, read_text, replace_text, strict_json
from ..validation import validate


class StateError(ValueError):
    """A state file that cannot be read; the message names the file and the problem."""


VERSION: Final = 2  # version 1 files (coordinates and band only) are read as they are


class BoardMark(BaseModel):
    """The board the state belongs to, as it stood when the state was written."""

    model_config = ConfigDict(extra="forbid")

    boot_id: int | None = None  # made by the board at its last reset (None: its firmware has none)
    motion_ticks: int  # its motion clock (at most): a clock that went back since means a reset
    position: list[int]  # its step counts


class StateFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    version: Literal[1, 2] = VERSION
    coordinates: WorkCoordinates = WorkCoordinates()
    band: BandRecord | None = None  # where each carriage sits in its backlash (backlash/band.py)
    homed: bool = False  # machine zero found (quadstep home) on this board since its last reset
    position_lost: bool = False  # a hard limit or the abort button lost it since
    board: BoardMark | None = None


def state_dir() -> Path:
    return Path(os.environ.get("XDG_STATE_HOME") or Path.home() / ".local" / "state") / "quadstep"


def state_path(config_path: Path | None) -> Path:
    """Where the state of the machine described by `config_path` (None: the generic one) is kept."""
    if config_path is None:
        return state_dir() / "default.json"
    resolved = config_path.resolve()
    digest = hashlib.sha256(str(resolved).encode()).hexdigest()[:8]
    return state_dir() / f"{resolved.stem}-{digest}.json"


def read_state(path: Path) -> StateFile:
    """What `path` keeps; nothing (all zero, G54) when there is no file yet."""
    if not path.exists():
        return StateFile()
    text = read_text(path, StateError, SETTINGS_MAX_BYTES)
    try:
        data = parse_nested(strict_json, text, path, StateError)
    except json.JSONDecodeError as exc:
        raise StateError(f"{path}: not valid JSON: {exc}") from None
    return validate(StateFile, data, str(path), StateError)


def load_state(path: Path) -> WorkCoordinates:
    """The work coordinates kept in `path`; all zero, G54, when there is no file yet."""
    return read_state(path).coordinates


def write_state(path: Path, state: StateFile) -> None:
    """Replace `path`, atomically, with `state` (in the current version)."""
    text = state.model_copy(update={"version": VERSION}).model_dump_json(indent=1)
    replace_text(path, text + "\n")


def save_state(path: Path, coordinates: WorkCoordinates) -> None:
    """Replace the work coordinates kept in `path`, atomically, keeping the rest."""
    write_state(path, read_state(path).model_copy(update={"coordinates": coordinates}))
