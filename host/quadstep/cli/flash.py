"""`quadstep flash --board uno|uno-laser|mega [--port PORT]`: write the quadstep firmware to a
board with avrdude (uno-laser: the Uno's build with laser rasters in place of cubic segments).

The hex is build/avr/<board>.hex of this source tree, built (`make <hex>`) when missing, or --hex
FILE. avrdude talks to the Arduino bootloader: `-c arduino` at 115200 baud for the Uno (57600 for
old Nano bootloaders: --bootloader-baud), `-c wiring` for the Mega; its progress bars are shown as
it prints them.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from ..emulator import REPO
from ..link import auto_port
from ..link.ports import PortError
from .options import CliError

# board → (avrdude part, programmer, bootloader baud)
BOARDS = {
    "uno": ("atmega328p", "arduino", 115200),
    "uno-laser": ("atmega328p", "arduino", 115200),  # RASTER in place of the cubic segments
    "mega": ("atmega2560", "wiring", 115200),
}


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "flash",
        help="write the quadstep firmware to an Uno, an Uno for a laser, or a Mega (avrdude)",
    )
    parser.add_argument(
        "--board",
        choices=sorted(BOARDS),
        required=True,
        help="uno-laser: the Uno's build with laser rasters (RASTER) in place of jerk-limited "
        "(cubic) segments",
    )
    parser.add_argument(
        "--port",
        default="auto",
        metavar="PORT",
        help="the board's serial port (default auto: the one Uno, Mega or clone on USB)",
    )
    parser.add_argument(
        "--hex", type=Path, metavar="FILE", help="write this hex instead of the built firmware"
    )
    parser.add_argument(
        "--bootloader-baud",
        type=int,
        metavar="BAUD",
        help="the bootloader's baud rate (default 115200; old Nano clones: 57600)",
    )
    parser.add_argument(
        "--dry-run",
        action="store_true",
        help="print the avrdude command instead of running it (PORT when no board is found)",
    )
    parser.set_defaults(handler=run)


def built_hex(board: str) -> Path:
    """build/avr/<board>.hex of this source tree, made with `make` when it is not there."""
    path = REPO / "build" / "avr" / f"{board}.hex"
    if not path.is_file():
        if not (REPO / "Makefile").is_file():
            raise CliError(f"{path} is not built and there is no source tree here: give --hex FILE")
        print(f"building {path.relative_to(REPO)} …", file=sys.stderr, flush=True)
        result = subprocess.run(
            ["make", "-C", str(REPO), f"build/avr/{board}.hex"], capture_output=True, text=True
        )
        if result.returncode != 0 or not path.is_file():
            raise CliError(
                f"building the firmware failed (it needs gcc-avr and avr-libc):\n"
                f"{result.stdout[-1500:]}{result.stderr[-1500:]}"
            )
    return path


def avrdude_command(
    board: str, port: str, hex_file: Path, baud: int | None = None, programmer: str | None = None
) -> list[str]:
    """The avrdude command line that writes `hex_file` through the board's bootloader (and verifies
    it)."""
    part, bootloader, default_baud = BOARDS[board]
    return [
        "avrdude",
        "-p",
        part,
        "-c",
        programmer or bootloader,
        "-P",
        port,
        "-b",
        str(baud or default_baud),
        "-D",
        "-U",
        f"flash:w:{hex_file}:i",
    ]


def run(args: argparse.Namespace) -> int:
    hex_file = args.hex if args.hex is not None else built_hex(args.board)
    if not hex_file.is_file():
        raise CliError(f"--hex {hex_file}: no such file")
    port = args.port
    if port == "auto":
        try:
            port = auto_port(instead="give --port PORT")
        except PortError as exc:
            if not args.dry_run:
                raise CliError(str(exc)) from None
            port = "PORT"  # a dry run shows the command with the port still to fill in
    command = avrdude_command(args.board, port, hex_file, args.bootloader_baud)
    if args.dry_run:
        print(" ".join(command))
        return 0
    if shutil.which("avrdude") is None:
        raise CliError("avrdude is not installed (Debian and Ubuntu: sudo apt-get install avrdude)")
    print(f"writing {hex_file} to the {args.board} on {port} …", file=sys.stderr, flush=True)
    result = subprocess.run(command)  # avrdude's progress bars go straight to the terminal
    if result.returncode != 0:
        raise CliError(
            f"avrdude failed (exit code {result.returncode}); is the port right and nothing else "
            "holding it (a sender, the TUI)?"
        )
    print(
        f"flashed: quadstep firmware on the {args.board} at {port}; `quadstep info --port {port}` "
        "shows it"
    )
    return 0
