"""Connecting to a board: --port auto by USB identity, a board that runs GRBL named as such (a fake GRBL on a
real pseudo-terminal), the default machine without a configuration, --version, send given G-code."""

from __future__ import annotations

import os
import threading
import tty
from collections.abc import Iterator
from pathlib import Path

import pytest
import serial
from serial.tools.list_ports_common import ListPortInfo

from quadstep import __version__
from quadstep.cli import main
from quadstep.link import auto_port, find_boards
from quadstep.link.ports import PortError

REPO = Path(__file__).resolve().parents[2]
GRBL_BANNER = b"\r\nGrbl 1.1h ['$' for help]\r\n"


def usb_port(device: str, vid: int | None, pid: int | None) -> ListPortInfo:
    info = ListPortInfo(device, skip_link_detection=True)
    info.vid, info.pid = vid, pid
    return info


@pytest.fixture
def ports(monkeypatch: pytest.MonkeyPatch) -> list[ListPortInfo]:
    """The USB ports the listing reports (nothing real to plug in here: pyserial's listing reads sysfs)."""
    listed: list[ListPortInfo] = []
    monkeypatch.setattr("serial.tools.list_ports.comports", lambda *a, **k: list(listed))
    return listed


def test_auto_finds_the_one_board_by_usb_identity(ports: list[ListPortInfo]) -> None:
    ports += [usb_port("/dev/ttyS0", None, None), usb_port("/dev/ttyUSB0", 0x1A86, 0x7523),
              usb_port("/dev/ttyACM3", 0x046D, 0xC52B)]  # a serial console, a CH340 clone, a mouse receiver
    assert [str(b) for b in find_boards()] == ["/dev/ttyUSB0 (CH340 (Uno/Nano/Mega clone))"]
    assert auto_port() == "/dev/ttyUSB0"


def test_auto_refuses_none_or_several(ports: list[ListPortInfo], capsys: pytest.CaptureFixture[str]) -> None:
    ports.append(usb_port("/dev/ttyS0", None, None))
    with pytest.raises(PortError, match=r"no Arduino Uno, Mega or clone found on USB \(serial ports: /dev/ttyS0\)"):
        auto_port()
    assert main(["info"]) == 1  # no --port: auto
    assert "--emulator runs without a board" in capsys.readouterr().err
    ports += [usb_port("/dev/ttyACM0", 0x2341, 0x0043), usb_port("/dev/ttyACM1", 0x2341, 0x0042)]
    with pytest.raises(PortError, match=r"2 boards found \(/dev/ttyACM0 \(Arduino Uno\), /dev/ttyACM1 \(Arduino "
                                        r"Mega 2560\)\): give --port with one of them"):
        auto_port()
    assert main(["ports"]) == 0
    assert capsys.readouterr().out == "/dev/ttyACM0 (Arduino Uno)\n/dev/ttyACM1 (Arduino Mega 2560)\n"


def test_flash_without_a_board_names_only_what_flash_takes(ports: list[ListPortInfo], tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    hex_file = tmp_path / "uno.hex"  # any image: the board is looked for before it is read
    hex_file.write_text(":00000001FF\n")
    assert main(["flash", "--board", "uno", "--hex", str(hex_file)]) == 1
    err = capsys.readouterr().err
    assert err.endswith("no Arduino Uno, Mega or clone found on USB: plug it in, or give --port PORT\n")
    assert "--emulator" not in err  # flash has no emulator to write to
    assert main(["flash", "--board", "uno", "--hex", str(hex_file), "--dry-run"]) == 0
    assert capsys.readouterr().out == f"avrdude -p atmega328p -c arduino -P PORT -b 115200 -D -U flash:w:{hex_file}:i\n"


@pytest.fixture
def fake_grbl() -> Iterator[str]:
    """A pseudo-terminal answering as GRBL does: its banner, then `ok` or `error:` for what it is sent."""
    main_fd, sub_fd = os.openpty()
    tty.setraw(sub_fd)  # as a USB serial port is: no echo, no line editing
    path = os.ttyname(sub_fd)
    stop = threading.Event()

    def serve() -> None:
        banner = GRBL_BANNER  # a board reset by the port's opening prints it once it runs: here, on the first bytes
        while not stop.is_set():
            try:
                data = os.read(main_fd, 256)
            except OSError:
                return
            if data:
                os.write(main_fd, banner + (b"error:1\r\n" if b"\x00" in data else b"ok\r\n"))
                banner = b""

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield path
    stop.set()
    os.close(sub_fd)
    os.close(main_fd)
    thread.join(timeout=2)


def test_a_board_running_grbl_is_named(fake_grbl: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", "--port", fake_grbl]) == 1
    assert capsys.readouterr().err == ("quadstep info: error: this board runs GRBL, not quadstep firmware: flash "
                                       "it with `quadstep flash`\n")


def test_the_emulator_runs_a_job_without_a_configuration(emulator_binary: Path, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("QUADSTEP_EMULATOR", str(emulator_binary))
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    monkeypatch.chdir(tmp_path)  # no quadstep.toml here
    job = REPO / "examples" / "demo.gcode"
    assert main(["run", str(job), "--emulator", "--free"]) == 0
    out, err = capsys.readouterr()
    assert "no configuration given: using the built-in default machine (the router of " \
           "examples/router-uno.toml)" in err
    assert out.splitlines()[-1] == "every axis is exactly where the job put it"
    assert main(["run", str(job), "--port", "/dev/null"]) == 1  # a real board needs its configuration
    assert "no machine configuration: give --config FILE" in capsys.readouterr().err


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == f"quadstep {__version__}\n"


def test_send_given_gcode_points_to_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    job = tmp_path / "part.nc"
    job.write_text("(a part)\nG21 G90\nG0 X10\n")
    assert main(["send", str(job), "--emulator"]) == 1
    assert capsys.readouterr().err == (f"quadstep send: error: {job} is G-code: `quadstep run {job}` runs it (send "
                                       "streams a JSON file of raw segments, docs/HOST.md)\n")


def test_pyserial_opens_the_fake_grbl(fake_grbl: str) -> None:
    """The fake is a real terminal device: pyserial reads GRBL's banner from it as from a board."""
    with serial.Serial(fake_grbl, 115200, timeout=2) as port:
        port.write(b"$I\n")
        assert port.read(len(GRBL_BANNER) + 4) == GRBL_BANNER + b"ok\r\n"
