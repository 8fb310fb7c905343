"""A corpus of bad job files and configurations, each one refused with a clear error: every value of the example
configuration and of small move and raw-segment files replaced by the wrong kind of value (a string, a boolean, a
list, NaN, infinity, out of range), required keys left out, unknown ones added, files cut short, nested too deep,
not text, and G-code lines no controller could run. `check` reads a configuration or a job, `send` a raw-segment
file, both before touching any port: a file is accepted when the command gets that far."""

from __future__ import annotations

import contextlib
import io
import json
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
DEMO = REPO / "examples" / "demo.gcode"
NO_BOARD = "/dev/nonexistent-board"

KEY_LINE = re.compile(r"^(?P<key>[a-z_]+)\s*=\s*(?P<value>[^#]*?)\s*(#.*)?$")
NUMBER = re.compile(r"-?\d+(\.\d+)?")
REQUIRED_KEYS = ("tick_hz", "name", "steps_per_mm", "max_speed", "max_accel", "travel_min", "travel_max")
WRONG_NUMBERS = {"string": '"{v}"', "boolean": "true", "nan": "nan", "inf": "inf", "list": "[{v}]",
                 "table": "{{ value = {v} }}", "date": "1979-05-27"}
WRONG_JSON = {"string": lambda v: str(v), "boolean": lambda v: True, "null": lambda v: None,
              "list": lambda v: [v], "table": lambda v: {"value": v}}

MOVES = {"feed_unit": "mm/s", "moves": [{"to": {"X": 10, "Y": 5}, "feed": 20},
                                         {"by": {"Z": -1}, "feed": 5, "accel": 100},
                                         {"rapid_to": {"X": 0, "Y": 0}}, {"dwell": 0.5}]}
SEGMENTS = {"segments": [{"n": 1000, "axes": [{"axis": 0, "direction": 1, "v0": 0, "vn": 2048, "r": 0}]},
                         {"n": 1000, "axes": [{"axis": 0, "direction": 1, "v0": 2048, "vn": 0, "r": 0}]}]}
OPTIONAL = ("accel",)  # null is leaving it out
SEGMENTS_OUT_OF_RANGE = {"n": [0, -1, 65536], "axis": [-1, 4, 9], "direction": [0, 2, -2],
                         "v0": [-1, 4097], "vn": [-1, 4097], "r": [-4097, 4097]}
GCODE_LINES = ["G1 X1e999 F100", "G1 Xnan F100", "G1 Xinf F100", "G1 X--1 F100", "G1 X F100", "G1 X1 F0",
               "G1 X1 F-5", "G1 X1 X2 F100", "G2 X1 Y1 F100", "G4 P-1", "G1 X100000 F100", "G0 Y-50",
               "G1 X1 E5 F100", "G1 B5 F100", "G1 X1 F1e999", "X1 Y1 Z1 Q5", "G99 X1", "G1 X1\x00 F100",
               "G20 G21 X1", "G1 X(1 F100", "G1 X20 F0.0000000001", "G4 P3601",
               "G1 X" + "9" * 400 + " F100", "G2 X10 Y10 I-100000000000000 F100"]


@dataclass(frozen=True)
class BadFile:
    name: str
    data: bytes

    def command(self, path: Path) -> list[str]:
        """The quadstep command that reads it (before any port is opened)."""
        if self.name.endswith(".toml"):
            return ["check", str(DEMO), "--config", str(path)]
        if self.name.startswith("segments"):
            return ["send", str(path), "--port", NO_BOARD]
        return ["check", str(path), "--config", str(ROUTER)]


def _toml(name: str, text: str) -> BadFile:
    return BadFile(f"config-{name}.toml", text.encode())


def bad_configs() -> Iterator[BadFile]:
    lines = ROUTER.read_text().splitlines()
    for i, line in enumerate(lines):
        match = KEY_LINE.match(line)
        if not match:
            continue
        key, value = match["key"], match["value"]
        if NUMBER.fullmatch(value):
            wrong = {kind: form.format(v=value) for kind, form in WRONG_NUMBERS.items()}
        elif value in ("true", "false"):
            wrong = {"number": "1", "string": f'"{value}"'}
        else:
            wrong = {"number": "7", "boolean": "false", "list": f"[{value}]"}
        for kind, new in wrong.items():
            yield _toml(f"{i + 1}-{key}-{kind}", "\n".join(lines[:i] + [f"{key} = {new}"] + lines[i + 1:]))
        if key in REQUIRED_KEYS:
            yield _toml(f"{i + 1}-{key}-missing", "\n".join(lines[:i] + lines[i + 1:]))
        yield _toml(f"{i + 1}-{key}-cut", "\n".join(lines[:i] + [line[: max(1, len(key) // 2)]]))
        yield _toml(f"{i + 1}-{key}-twice", "\n".join(lines[: i + 1] + [line] + lines[i + 1:]))
    for i, line in enumerate(lines):
        if line.startswith("["):
            yield _toml(f"{i + 1}-unknown-key", "\n".join(lines[: i + 1] + ["stepz_per_mm = 400"] + lines[i + 1:]))
    yield _toml("empty", "")
    yield _toml("no-axes", "tick_hz = 32000\n")
    yield _toml("deep", "x = " + "[" * 600 + "]" * 600 + "\n")
    for key, value in (("steps_per_mm", "5e-324"), ("max_speed", "1e-300"), ("max_accel", "5e-324"),
                       ("travel_max", "0.001"), ("locate", "1e-9")):
        changed = re.sub(rf"^{key} = [^#\n]*", f"{key} = {value} ", "\n".join(lines), count=1,
                         flags=re.M)
        yield _toml(f"{key}-{value}", changed)
    yield BadFile("config-latin-1.toml", "# Fräse\ntick_hz = 32000\n".encode("latin-1"))
    yield BadFile("config-binary.toml", bytes(range(256)))


def _leaves(data: object, path: tuple = ()) -> Iterator[tuple]:
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, (*path, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            yield from _leaves(value, (*path, index))
    else:
        yield path


def _replaced(data: object, path: tuple, value: object) -> object:
    copy = json.loads(json.dumps(data))
    target = copy
    for step in path[:-1]:
        target = target[step]
    target[path[-1]] = value
    return copy


def _json_files(stem: str, good: dict, out_of_range: dict[str, list[int]]) -> Iterator[BadFile]:
    for leaf in _leaves(good):
        where = "-".join(str(step) for step in leaf)
        original = _get(good, leaf)
        for kind, make in WRONG_JSON.items():
            if (kind == "string" and not isinstance(original, (int, float))) or (kind == "null" and leaf[-1] in OPTIONAL):
                continue
            yield BadFile(f"{stem}-{where}-{kind}.json", json.dumps(_replaced(good, leaf, make(original))).encode())
        for bad in out_of_range.get(str(leaf[-1]), []):
            yield BadFile(f"{stem}-{where}-{bad}.json", json.dumps(_replaced(good, leaf, bad)).encode())
    for literal in ("NaN", "Infinity", "1e400"):
        text = json.dumps(good).replace(json.dumps(_first_number(good)), literal, 1)
        yield BadFile(f"{stem}-{literal.lower()}.json", text.encode())
    text = json.dumps(good)
    yield BadFile(f"{stem}-cut.json", text[: len(text) // 2].encode())
    yield BadFile(f"{stem}-unknown-key.json", text.replace("{", '{"extra": 1, ', 1).encode())
    yield BadFile(f"{stem}-list.json", b"[]")
    yield BadFile(f"{stem}-empty.json", b"")
    yield BadFile(f"{stem}-deep.json", ("[" * 1000 + "]" * 1000).encode())
    yield BadFile(f"{stem}-deeper.json", ('{"a": ' * 100_000 + "1" + "}" * 100_000).encode())
    key = next(iter(good))
    twice = text.replace("{", "{" + json.dumps(key) + ": " + json.dumps(good[key]) + ", ", 1)
    yield BadFile(f"{stem}-key-twice.json", twice.encode())


def _get(data: object, path: tuple) -> object:
    for step in path:
        data = data[step]  # type: ignore[index]
    return data


def _first_number(data: object) -> object:
    return next(_get(data, leaf) for leaf in _leaves(data) if type(_get(data, leaf)) in (int, float))


def bad_jobs() -> Iterator[BadFile]:
    yield from _json_files("moves", MOVES, {"feed": [0, -1, 1e-300], "accel": [0, -5, 1e-300],
                                            "dwell": [-1, 3601]})
    yield from _json_files("segments", SEGMENTS, SEGMENTS_OUT_OF_RANGE)
    yield BadFile("moves-deep.yaml", ("a:\n" + "".join("  " * i + "- \n" for i in range(1000))).encode())
    laughs = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{b}: &{b} [*{a}, *{a}, *{a}, *{a}, *{a}, *{a}, *{a}, *{a}, *{a}]\n" for a, b in zip("abcdefgh", "bcdefghi"))
    yield BadFile("moves-aliases.yaml", (laughs + "moves: *i\n").encode())
    yield BadFile("moves-tabs.yaml", b"moves:\n\t- dwell: 1\n")
    yield BadFile("moves-key-twice.yaml", b"moves:\n  - dwell: 1\nmoves:\n  - dwell: 2\n")
    yield BadFile("moves-field-twice.yaml", b"moves:\n  - {to: {X: 1}, feed: 1, feed: 2}\n")
    for i, line in enumerate(GCODE_LINES):
        yield BadFile(f"gcode-{i + 1:02d}.gcode", f"G21 G90\nG0 X10 Y10\n{line}\nG0 X0 Y0\n".encode())
    yield BadFile("gcode-latin-1.gcode", "(Fräse)\nG0 X1\n".encode("latin-1"))
    yield BadFile("gcode-dwells.gcode", b"G4 P3600\n" * 10_000)
    yield BadFile("moves-dwells.json", json.dumps({"moves": [{"dwell": 3600}] * 10_000}).encode())


def corpus() -> list[BadFile]:
    return [*bad_configs(), *bad_jobs()]


def judge(bad: BadFile, folder: Path) -> tuple[str, str]:
    """Run the command that reads `bad` (written into `folder`): ("refused" | "accepted" | "traceback", stderr)."""
    from quadstep.cli import main  # the commands, loaded once a corpus is judged

    path = folder / bad.name
    path.write_bytes(bad.data)
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main(bad.command(path))
    except SystemExit as exc:
        code = exc.code
    except Exception as exc:  # noqa: BLE001 - what escapes the command is the finding
        return "traceback", f"{type(exc).__name__}: {exc}"
    text = err.getvalue()
    if "Traceback" in text:
        return "traceback", text
    if code == 0 or NO_BOARD in text:
        return "accepted", text
    return "refused", text
