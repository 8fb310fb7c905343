"""`quadstep ports`: the serial ports whose USB identity is a board quadstep runs on (what --port
auto picks from)."""

from __future__ import annotations

import argparse

from serial.tools import list_ports

from ..link import find_boards


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "ports", help="list the boards on USB (Arduino Uno, Mega and their clones)"
    )
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    boards = find_boards()
    for board in boards:
        print(board)
    if not boards:
        others = [p.device for p in list_ports.comports()]
        print("no board found" + (f"; other serial ports: {', '.join(others)}" if others else ""))
    return 0
