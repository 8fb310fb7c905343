"""quadstep flash: the hex it writes, the avrdude command line, and avrdude itself writing and verifying that hex
through a bootloader: a small STK500v1 responder (the protocol of the Uno's bootloader) on a real
pseudo-terminal, since no board is plugged in here."""

from __future__ import annotations

import os
import shutil
import subprocess
import threading
import tty
from pathlib import Path

import pytest

from quadstep.cli import main
from quadstep.cli.flash import avrdude_command, built_hex

REPO = Path(__file__).resolve().parents[2]
INSYNC, OK, EOP = 0x14, 0x10, 0x20
ARGUMENTS = {0x30: 0, 0x41: 1, 0x42: 20, 0x50: 0, 0x51: 0, 0x55: 2, 0x56: 4, 0x75: 0}  # command → argument bytes


def read_hex(path: Path) -> dict[int, int]:
    """An Intel HEX file as address → byte, every record's checksum checked."""
    memory: dict[int, int] = {}
    base = 0
    for line in path.read_text().split():
        assert line.startswith(":")
        record = bytes.fromhex(line[1:])
        assert sum(record) % 256 == 0, f"bad checksum: {line}"
        length, address, kind = record[0], int.from_bytes(record[1:3], "big"), record[3]
        data = record[4:4 + length]
        if kind == 0:
            memory.update({base + address + i: b for i, b in enumerate(data)})
        elif kind == 2:
            base = int.from_bytes(data, "big") << 4
        elif kind == 4:
            base = int.from_bytes(data, "big") << 16
    return memory


class Bootloader:
    """Answers avrdude's `-c arduino` as an ATmega328P's bootloader does, into a flash of its own."""

    def __init__(self) -> None:
        self.main, sub = os.openpty()
        tty.setraw(sub)
        self.path = os.ttyname(sub)
        self.sub = sub
        self.flash: dict[int, int] = {}
        self.address = 0
        self.buffer = bytearray()
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)

    def _need(self, count: int) -> bytes:
        while len(self.buffer) < count:
            data = os.read(self.main, 4096)
            if not data:
                raise OSError("closed")
            self.buffer += data
        taken, self.buffer = bytes(self.buffer[:count]), self.buffer[count:]
        return taken

    def _serve(self) -> None:
        try:
            while not self.stop.is_set():
                command = self._need(1)[0]
                if command in ARGUMENTS:
                    args = self._need(ARGUMENTS[command])
                    reply = self._simple(command, args)
                elif command == 0x45:  # SET_DEVICE_EXT: its first byte counts itself and the rest
                    self._need(self._need(1)[0] - 1)
                    reply = b""
                elif command in (0x64, 0x74):  # PROG_PAGE / READ_PAGE: length, memory type, (data)
                    header = self._need(3)
                    length = int.from_bytes(header[:2], "big")
                    byte_address = self.address * 2
                    if command == 0x64:
                        for i, b in enumerate(self._need(length)):
                            self.flash[byte_address + i] = b
                        reply = b""
                    else:
                        reply = bytes(self.flash.get(byte_address + i, 0xFF) for i in range(length))
                else:
                    continue  # noise before sync: a bootloader ignores it
                if self._need(1)[0] != EOP:
                    continue
                os.write(self.main, bytes([INSYNC]) + reply + bytes([OK]))
        except OSError:
            return

    def _simple(self, command: int, args: bytes) -> bytes:
        if command == 0x55:
            self.address = int.from_bytes(args, "little")  # a word address
        if command == 0x41:
            return b"\x00"
        if command == 0x56:
            return b"\x00"
        if command == 0x75:
            return bytes([0x1E, 0x95, 0x0F])  # the ATmega328P's signature
        return b""

    def __enter__(self) -> Bootloader:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        os.close(self.sub)
        os.close(self.main)
        self.thread.join(timeout=2)


@pytest.fixture(scope="module")
def uno_hex() -> Path:
    return built_hex("uno")


def test_the_hex_is_the_firmware_s_flash_image(uno_hex: Path, tmp_path: Path) -> None:
    image = tmp_path / "uno.bin"
    subprocess.run(["avr-objcopy", "-O", "binary", "-R", ".eeprom", "-R", ".noinit",
                    str(uno_hex.with_suffix(".elf")), str(image)], check=True)
    memory = read_hex(uno_hex)
    assert sorted(memory) == list(range(len(memory)))  # one piece from address 0
    assert bytes(memory[a] for a in range(len(memory))) == image.read_bytes()
    assert len(memory) <= 32768 - 512  # below the Uno's bootloader


def test_the_avrdude_command_line(uno_hex: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert avrdude_command("uno", "/dev/ttyUSB0", uno_hex) == [
        "avrdude", "-p", "atmega328p", "-c", "arduino", "-P", "/dev/ttyUSB0", "-b", "115200", "-D",
        "-U", f"flash:w:{uno_hex}:i"]
    assert avrdude_command("mega", "/dev/ttyACM0", uno_hex)[:9] == [
        "avrdude", "-p", "atmega2560", "-c", "wiring", "-P", "/dev/ttyACM0", "-b", "115200"]
    assert main(["flash", "--board", "uno", "--port", "/dev/ttyUSB0", "--bootloader-baud", "57600",
                 "--dry-run"]) == 0
    assert capsys.readouterr().out == (f"avrdude -p atmega328p -c arduino -P /dev/ttyUSB0 -b 57600 -D "
                                       f"-U flash:w:{uno_hex}:i\n")


@pytest.mark.skipif(shutil.which("avrdude") is None, reason="avrdude is installed by make setup")
def test_avrdude_writes_and_verifies_the_firmware_through_the_bootloader(uno_hex: Path, capfd) -> None:
    with Bootloader() as bootloader:
        assert main(["flash", "--board", "uno", "--port", bootloader.path]) == 0
        written = dict(bootloader.flash)
    out, err = capfd.readouterr()
    image = read_hex(uno_hex)
    assert {a: written[a] for a in image} == image  # every byte of the hex, where the hex puts it
    assert {written[a] for a in written if a not in image} <= {0xFF}  # the last page filled as erased
    assert max(written) < 128 * (max(image) // 128 + 1)  # and nothing past it
    assert "Writing | ################################################## | 100%" in err  # avrdude's progress
    assert "bytes of flash verified" in err
    assert out.endswith(f"flashed: quadstep firmware on the uno at {bootloader.path}; "
                        f"`quadstep info --port {bootloader.path}` shows it\n")


def test_a_missing_hex_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["flash", "--board", "uno", "--port", "/dev/null", "--hex", str(tmp_path / "x.hex")]) == 1
    assert capsys.readouterr().err == f"quadstep flash: error: --hex {tmp_path / 'x.hex'}: no such file\n"
