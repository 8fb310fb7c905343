"""`quadstep grbl`: serve GRBL 1.1 on a pseudo-terminal (and TCP) so that a G-code sender drives the
machine (docs/SENDERS.md)."""

from __future__ import annotations

import argparse
import sys
import threading
from pathlib import Path

from ..grbl.server import PtyServer, TcpServer
from ..grbl.session import SessionOptions
from ..machine import Machine
from ._jobs import machine_config
from .options import CliError, add_connection_options, config_path, connect


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "grbl",
        help="serve GRBL 1.1 to a G-code sender (UGS, CNCjs, bCNC, Candle, LightBurn) on a "
        "pseudo-terminal or TCP",
    )
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="machine configuration (default ./quadstep.toml)",
    )
    parser.add_argument(
        "--link",
        type=Path,
        metavar="PATH",
        help="a symbolic link at PATH to the pseudo-terminal, a name that stays the same",
    )
    parser.add_argument(
        "--tcp",
        type=tcp_port,
        metavar="PORT",
        help="also serve on TCP 127.0.0.1:PORT (UGS tcp://, bCNC socket://)",
    )
    parser.add_argument(
        "--m6",
        choices=("ignore", "pause"),
        default="ignore",
        help="M6 tool change: answered ok and ignored, the sender handles it (GRBL's default), "
        "or a pause held until cycle start (~), as quadstep run does",
    )
    add_connection_options(parser)
    parser.set_defaults(handler=run)


def tcp_port(text: str) -> int:
    """--tcp: a TCP port number, 0 (any free one) … 65535."""
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"{port} is outside 0 … 65535")
    return port


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    if args.link is not None and args.link.exists() and not args.link.is_symlink():
        raise CliError(f"--link {args.link}: a file is there already (not a link)")
    with connect(args, config, str(args.config or "quadstep.toml")) as machine:
        options = SessionOptions.of(machine, args.m6, config_path(args))
        pty = PtyServer(machine, args.link, options)
        tcp = None
        try:
            link = f" (link {args.link})" if args.link else ""
            print(f"GRBL 1.1 on {pty.path}{link}", flush=True)
            if args.tcp is not None:
                tcp = start_tcp(machine, args.tcp, options)
                print(f"GRBL 1.1 on tcp://127.0.0.1:{tcp.port}", flush=True)
            print("Ctrl-C ends it", file=sys.stderr, flush=True)
            pty.serve()
        except KeyboardInterrupt:
            pty.stop()
        finally:
            if tcp is not None:
                tcp.close()
            pty.close()
    return 0


def start_tcp(machine: Machine, port: int, options: SessionOptions) -> TcpServer:
    def connected(who: str) -> None:
        print(f"sender connected from {who}", file=sys.stderr, flush=True)

    try:
        server = TcpServer(machine, port, on_client=connected, options=options)
    except OSError as exc:
        raise CliError(
            f"--tcp {port}: cannot listen on 127.0.0.1:{port} ({exc.strerror})"
        ) from None
    return server.start()


def serve_in_thread(pty: PtyServer) -> threading.Thread:
    """For tests and embedding: the pseudo-terminal served by a thread of its own."""
    thread = threading.Thread(target=pty.serve, name="grbl-pty", daemon=True)
    thread.start()
    return thread
