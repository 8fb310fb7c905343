"""The state file: the work coordinates of one machine, kept across runs.

One file per machine configuration, at

    $XDG_STATE_HOME/quadstep/<config name>-<8 hex digits>.json   (XDG_STATE_HOME defaults to ~/.local/state)

where the digits come from the configuration file's absolute path (two files
of one name in different folders are two machines), and `default.json` for
the generic configuration. It is replaced whole and atomically (written
beside it, flushed to disk, renamed over it), so a crash leaves the old file
or the new one, never half of either.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict

from ..backlash.band import BandRecord
from ..config import validate
from ..coordinates import WorkCoordinates
from ..textfile import SETTINGS_MAX_BYTES, parse_nested, read_text, replace_text, strict_json


class StateError(ValueError):
    """A state file that cannot be read; the message names the file and the problem."""


class StateFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    version: Literal[1] = 1
    coordinates: WorkCoordinates = WorkCoordinates()
    band: BandRecord | None = None  # where each carriage sits in its backlash (backlash/band.py)


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


def save_state(path: Path, coordinates: WorkCoordinates | None = None, band: BandRecord | None = None) -> None:
    """Replace `path`, atomically, with these coordinates and band (either one not given: the one kept)."""
    kept = read_state(path) if coordinates is None or band is None else StateFile()
    state = StateFile(coordinates=coordinates if coordinates is not None else kept.coordinates,
                      band=band if band is not None else kept.band)
    replace_text(path, state.model_dump_json(indent=1) + "\n")
