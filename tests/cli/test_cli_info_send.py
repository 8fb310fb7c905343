"""The `quadstep` command line: info and send, on the emulator; input errors before anything moves."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from quadstep.cli import build_parser, info, main, send
from quadstep.cli.send import load
from quadstep.config import load_config
from quadstep.kernel.engine_model import predict

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "raw-segments.json"


def test_commands_are_discovered() -> None:
    parser = build_parser()
    assert parser.parse_args(["info", "--emulator"]).handler is info.run
    assert parser.parse_args(["send", "job.json", "--port", "/dev/ttyACM0"]).handler is send.run


def test_module_entry_point_runs() -> None:
    result = subprocess.run([sys.executable, "-m", "quadstep.cli", "--help"], capture_output=True, text=True)
    assert result.returncode == 0 and "send" in result.stdout and "info" in result.stdout


def test_info_json(emulator_binary: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("QUADSTEP_EMULATOR", str(emulator_binary))
    assert main(["info", "--emulator", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    # the emulator started without a configuration is the default machine: examples/router-uno.toml's
    default = load_config(REPO / "examples" / "router-uno.toml")
    assert out["identify"]["protocol_version"] == 3 and out["identify"]["axis_count"] == len(default.axes) == 3
    assert out["identify"]["tick_hz"] == default.tick_hz == 32000
    assert out["status"]["state"] == "IDLE" and out["status"]["position"] == [0, 0, 0]


def test_info_text(emulator_binary: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("QUADSTEP_EMULATOR", str(emulator_binary))
    assert main(["info", "--emulator"]) == 0
    out = capsys.readouterr().out
    assert "on EMULATOR, protocol 3" in out and "32000 Hz" in out and "X 0  Y 0  Z 0\n" in out
    assert "laser rasters: a ring of 1024 powers" in out


def test_send_example(emulator_binary: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                      tmp_path: Path) -> None:
    monkeypatch.setenv("QUADSTEP_EMULATOR", str(emulator_binary))
    trace = tmp_path / "trace.csv"
    assert main(["send", str(EXAMPLE), "--emulator", "--free", "--json", "--trace", str(trace)]) == 0
    out = json.loads(capsys.readouterr().out)
    job = load(EXAMPLE)
    expected = predict(job.segments, positions=[0, 100, 0], axis_count=3)
    assert out["positions"] == expected.positions == [1000, -150, 0]
    assert out["segments"] == 3 and out["motion_ticks"] == 3000
    assert out["link"]["retransmits"] == 0 and out["link"]["frames_sent"] >= 4
    assert trace.read_text().count("\n") == 1 + 1000 + 250


def test_send_text(emulator_binary: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("QUADSTEP_EMULATOR", str(emulator_binary))
    assert main(["send", str(EXAMPLE), "--emulator", "--free"]) == 0
    assert "positions (steps): X 1000  Y -150  Z 0\n" in capsys.readouterr().out


@pytest.mark.parametrize(
    "content, message",
    [
        ('{"segments": [{"n": 0, "axes": []}]}',
         "segments[0].n = 0: must be at least 1"),
        ('{"segments": [{"n": 5, "axes": []}, {"n": 5, "axes": [{"axis": 1, "direction": 1, "v0": 4097, "vn": 0, "r": 0}]}]}',
         "segments[1].axes[0].v0 = 4097: must be at most 4096"),
        ('{"segments": [{"n": 5, "axes": [{"axis": 0, "direction": 1, "v0": 0, "vn": 0, "r": -4097}]}]}',
         "segments[0].axes[0].r = -4097: must be at least -4096"),
        ('{"segments": [{"n": 5, "axes": [{"axis": 0, "direction": 0, "v0": 0, "vn": 0, "r": 0}]}]}',
         "segments[0].axes[0].direction = 0: must be one of 1 or -1"),
        ('{"segments": [{"n": 5, "axes": [{"axis": 2, "direction": 1, "v0": 0, "vn": 0, "r": 0},'
         ' {"axis": 1, "direction": 1, "v0": 0, "vn": 0, "r": 0}]}]}',
         "segments[0].axes: axes must be listed once each in ascending order, got [2, 1]"),
        ('{"segments": [{"n": 5, "axes": [{"axis": 0, "direction": 1, "v0": 4096, "vn": 4096, "r": 4096}]}]}',
         "segments[0].axes[0].r = 4096 with v0 = vn = 4096 would trail the ideal"),
        ('{"segments": [{"n": 5, "axes": [{"axis": 0, "direction": 1, "v0": 0, "vn": 10, "r": 0}]}]}',
         "segments[0]: the last segment must end at rest, but axis 0 ends at vn > 0"),
        ('{"segments": []}', "segments = []: needs at least 1 entry"),
        ('{"segments": [{"n": 5}], "extra": 1}', "extra: unknown key"),
        ('{"positions": [1, 2, 3, 4, 5], "segments": [{"n": 5}]}', "positions = [1, 2, 3, 4, 5]: allows at most 4 entries"),
        ('{"segments": [', "line 1 column 15: Expecting value"),
    ],
)
def test_send_refuses_bad_files_before_connecting(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  content: str, message: str) -> None:
    path = tmp_path / "job.json"
    path.write_text(content)
    # --port names a device that does not exist: a file error must come first.
    assert main(["send", str(path), "--port", "/dev/nonexistent-quadstep"]) == 1
    err = capsys.readouterr().err
    assert f"{path}" in err and message in err


def test_send_refuses_a_file_that_is_not_text(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "job.json"
    path.write_bytes(b'{"segments": \xff}')
    assert main(["send", str(path), "--port", "/dev/nonexistent-quadstep"]) == 1
    assert capsys.readouterr().err == f"quadstep send: error: {path}: not a text file (invalid start byte at byte 13)\n"


def test_send_refuses_axes_the_firmware_lacks(start_emulator, capsys: pytest.CaptureFixture[str],
                                              tmp_path: Path) -> None:
    emu = start_emulator(free=True, axes=3)
    path = tmp_path / "job.json"
    path.write_text('{"segments": [{"n": 5, "axes": [{"axis": 3, "direction": 1, "v0": 10, "vn": 0, "r": 0}]}]}')
    assert main(["send", str(path), "--port", emu.url]) == 1
    assert "segments[0].axes[0].axis: 3, the firmware has axes 0..2" in capsys.readouterr().err


def test_free_needs_the_emulator(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", "--port", "/dev/null", "--free"]) == 1
    assert "--free and --trace apply only with --emulator" in capsys.readouterr().err


def test_port_and_emulator_are_exclusive(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["info", "--port", "/dev/null", "--emulator"])
    assert "not allowed with argument" in capsys.readouterr().err
