"""Job files and configurations are read strictly: no string or boolean is ever taken for a number; input nested or
sized past reason is one clear error, never a traceback; nothing is sent (the command stops before connecting)."""

from __future__ import annotations

from pathlib import Path

import pytest

from quadstep.cli import main

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"

ROUTER_TEXT = ROUTER.read_text()
BAD_FILES = {
    "moves-string-coordinate.json": ('{"moves": [{"to": {"X": "10"}, "feed": 100}]}', 'moves[0].to.X = \'10\''),
    "moves-boolean-feed.json": ('{"moves": [{"to": {"X": 10}, "feed": true}]}', "moves[0].feed = True"),
    "moves-string-feed.yaml": ('moves:\n  - by: {Y: 1}\n    feed: "300"\n', "moves[0].feed = '300'"),
    "segments-string-n.json": ('{"segments": [{"n": "100", "axes": []}]}', "segments[0].n = '100'"),
    "segments-boolean-direction.json": (
        '{"segments": [{"n": 10, "axes": [{"axis": 0, "direction": true, "v0": 0, "vn": 0, "r": 0}]}]}',
        "segments[0].axes[0].direction"),
    "deep.json": ("[" * 1000 + "]" * 1000, "nested too deep"),
    "deep.yaml": ("a:\n" + "".join("  " * i + "- \n" for i in range(1000)), "nested too deep"),
}
BAD_CONFIGS = {
    "string-steps.toml": (ROUTER_TEXT.replace("steps_per_mm = 400", 'steps_per_mm = "400"', 1),
                          "steps_per_mm = '400'"),
    "string-invert.toml": (ROUTER_TEXT.replace("invert = false", 'invert = "yes"', 1), "invert = 'yes'"),
    "boolean-tick.toml": (ROUTER_TEXT.replace("tick_hz = 32000", "tick_hz = true", 1), "tick_hz = True"),
    "deep.toml": ("x = " + "[" * 600 + "]" * 600 + "\n", "nested too deep"),
    "travel-past-positions.toml": (ROUTER_TEXT.replace("steps_per_mm = 400", "steps_per_mm = 40000", 1)
                                   .replace("travel_max = 300", "travel_max = 60000", 1),
                                   "travel_max = 60000: must be within ±53268 mm, the firmware's position range"),
}


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_a_bad_job_file_is_one_clear_error_and_nothing_moves(name: str, tmp_path: Path, capsys) -> None:
    text, expected = BAD_FILES[name]
    path = tmp_path / name
    path.write_text(text)
    command = "send" if name.startswith("segments") or name == "deep.json" else "run"
    args = [command, str(path), "--port", "/dev/nonexistent-board"]
    if command == "run":
        args += ["--config", str(ROUTER)]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert expected in err, err
    assert "Traceback" not in err and "nonexistent-board" not in err  # refused before connecting


@pytest.mark.parametrize("name", sorted(BAD_CONFIGS))
def test_a_bad_configuration_is_one_clear_error(name: str, tmp_path: Path, capsys) -> None:
    text, expected = BAD_CONFIGS[name]
    assert text != ROUTER_TEXT or name.startswith("deep")
    path = tmp_path / name
    path.write_text(text)
    assert main(["check", str(REPO / "examples" / "demo.gcode"), "--config", str(path)]) == 1
    err = capsys.readouterr().err
    assert expected in err, err
    assert "Traceback" not in err


def test_gcode_lines_end_at_newlines_only(tmp_path: Path, capsys) -> None:
    """A file separator (0x1c) or a Unicode line separator inside a line does not start a new line: the line
    numbers in errors are an editor's."""
    path = tmp_path / "job.gcode"
    path.write_text("G21 G90 F600\nG1 X1 \u2028 Y2\nG1 X2\n")
    assert main(["check", str(path), "--config", str(ROUTER)]) == 1
    assert "line 2" in capsys.readouterr().err


@pytest.mark.parametrize("port, message", [("socket://nohost", "socket://HOST:PORT"),
                                            ("/dev/null", "")])
def test_connection_options_are_checked(port: str, message: str, capsys) -> None:
    if message:
        assert main(["info", "--port", port]) == 1
        assert message in capsys.readouterr().err
    else:
        with pytest.raises(SystemExit) as caught:
            main(["info", "--port", port, "--baud", "0"])
        assert caught.value.code == 2
        assert "--baud: 0 is outside" in capsys.readouterr().err
