"""`quadstep grbl`: serve GRBL 1.1 on a pseudo-terminal (and TCP) so that a G-code sender drives the
machine (docs/SENDERS.md)."""

from __future__ import annotations

import argparse
import sys
import threading
from pathlib import Path

from ..grbl.server import PtyServer, TcpServer
from ._jobs import machine_config
from .options import add_connection_options, connect


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "grbl",
        help="serve GRBL 1.1 to a G-code sender (UGS, CNCjs, bCNC, "
        "Candle, LightBurn) on a pseudo-terminal or TCP",
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
        type=int,
        metavar="PORT",
        help="also serve on TCP 127.0.0.1:PORT (UGS tcp://, bCNC socket://)",
    )
    add_connection_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = machine_config(args)
    with connect(args, config, str(args.config or "quadstep.toml")) as machine:
        pty = PtyServer(machine, args.link)
        tcp = None
        try:
            print(
                f"GRBL 1.1 on {pty.path}" + (f" (link {args.link})" if args.link else ""),
                flush=True,
            )
            if args.tcp is not None:
                tcp = TcpServer(
                    machine,
                    args.tcp,
                    on_client=lambda who: print(
                        f"sender connected from {who}", file=sys.stderr, flush=True
                    ),
                ).start()
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


def serve_in_thread(pty: PtyServer) -> threading.Thread:
    """For tests and embedding: the pseudo-terminal served by a thread of its own."""
    thread = threading.Thread(target=pty.serve, name="grbl-pty", daemon=True)
    thread.start()
    return thread
