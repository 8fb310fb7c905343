"""Move files: scripted batch moves as JSON or YAML, validated whole by pydantic.

    {"feed_unit": "mm/s",                  # or "mm/min"; applies to every feed
     "moves": [
        {"to": {"X": 10, "Y": 5}, "feed": 20},
        {"by": {"Z": -1}, "feed": 5, "accel": 100},
        {"rapid_to": {"X": 0, "Y": 0}},
        {"dwell": 0.5},
        {"pause": true}]}

Coordinates are machine coordinates in mm; `to` is absolute, `by` relative,
`rapid_to`/`rapid_by` move at each axis's maximum speed. `accel` (mm/s²)
lowers the acceleration along the path for that move. See docs/JOBS.md.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, model_validator

from .config import AxisName
from .planner.program import MAX_DWELL_S, Dwell, JobError, LinearMove, Pause, Program
from .textfile import DuplicateKeyError, parse_nested, read_text, strict_json
from .validation import validate

Coordinates = dict[AxisName, float]


class Move(BaseModel):
    """One entry of `moves`: exactly one of to / by / rapid_to / rapid_by / dwell / pause."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    to: Coordinates | None = None
    by: Coordinates | None = None
    rapid_to: Coordinates | None = None
    rapid_by: Coordinates | None = None
    feed: Annotated[float, Field(gt=0)] | None = None
    accel: Annotated[float, Field(gt=0)] | None = None
    dwell: Annotated[float, Field(ge=0, le=MAX_DWELL_S)] | None = None
    pause: Literal[True] | None = None

    @model_validator(mode="after")
    def _one_kind(self) -> Move:
        kinds = [
            k
            for k in ("to", "by", "rapid_to", "rapid_by", "dwell", "pause")
            if getattr(self, k) is not None
        ]
        if len(kinds) != 1:
            raise ValueError(
                "needs exactly one of to, by, rapid_to, rapid_by, dwell, pause (got "
                f"{kinds or 'none'})"
            )
        kind = kinds[0]
        if kind in ("to", "by") and self.feed is None:
            raise ValueError(f"'{kind}' needs a feed")
        if kind not in ("to", "by") and self.feed is not None:
            raise ValueError(f"feed applies only to 'to' and 'by' moves, not '{kind}'")
        if kind in ("dwell", "pause") and self.accel is not None:
            raise ValueError(f"accel applies only to moves, not '{kind}'")
        return self


class MoveFile(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    feed_unit: Literal["mm/s", "mm/min"] = "mm/s"
    moves: list[Move] = Field(min_length=1)


class _UniqueKeyLoader(yaml.SafeLoader):
    """YAML's safe loader, except that a key given twice in one mapping is refused (not the last
    one kept)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[str] = set()
        for key, _ in node.value:
            if isinstance(key, yaml.ScalarNode) and key.value in seen:
                raise DuplicateKeyError(
                    f"line {key.start_mark.line + 1}: key {key.value!r} is "
                    "given twice in one mapping (which one is meant?)"
                )
            seen.add(key.value if isinstance(key, yaml.ScalarNode) else "")
        return super().construct_mapping(node, deep)


def _strict_yaml(text: str) -> Any:
    return yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 - a safe loader


def read_move_file(path: Path) -> MoveFile:
    """Load and validate; errors name the move index and field."""
    text = read_text(path, JobError)
    try:
        parse = _strict_yaml if path.suffix.lower() in (".yaml", ".yml") else strict_json
        data: Any = parse_nested(parse, text, path, JobError)
    except (yaml.YAMLError, json.JSONDecodeError) as exc:
        kind = "YAML" if path.suffix.lower() in (".yaml", ".yml") else "JSON"
        raise JobError(f"{path}: not valid {kind}: {exc}") from None
    return validate(MoveFile, data, str(path), JobError)


def move_program(moves: MoveFile, axis_names: Sequence[str], start: Sequence[float]) -> Program:
    """Moves in machine coordinates; `line` of each item is the 1-based move number."""
    scale = 1.0 if moves.feed_unit == "mm/s" else 1.0 / 60.0
    position = [float(x) for x in start]
    program = Program(lines=len(moves.moves))
    for number, move in enumerate(moves.moves, start=1):
        if move.dwell is not None:
            program.items.append(Dwell(number, move.dwell))
            continue
        if move.pause:
            program.items.append(Pause(number))
            continue
        coords = move.to or move.by or move.rapid_to or move.rapid_by or {}
        relative = move.by is not None or move.rapid_by is not None
        for letter, value in coords.items():
            if letter not in axis_names:
                raise JobError(
                    f"move {number}: axis {letter} is not on this machine (axes "
                    f"{', '.join(axis_names)})"
                )
            i = list(axis_names).index(letter)
            position[i] = position[i] + value if relative else value
        feed = move.feed * scale if move.feed is not None else None
        program.items.append(LinearMove(number, tuple(position), feed, move.accel))
    return program
