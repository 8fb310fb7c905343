"""`quadstep info`: what the firmware is, and its status."""

from __future__ import annotations

import argparse
import json

from ..protocol import AXIS_NAMES, IdentifyReply, StatusReport
from .options import add_connection_options, add_json_option, connect

COUNTERS = ("rx_overrun", "bad_frame", "bad_crc", "seq_gap", "seq_dup", "rejected")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("info", help="identify the firmware and show its status")
    add_connection_options(parser)
    add_json_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    with connect(args) as machine:
        ident = machine.identity
        status = machine.status()
    if args.json:
        print(
            json.dumps(
                {
                    "identify": ident.model_dump(mode="json"),
                    "status": status.model_dump(mode="json"),
                }
            )
        )
    else:
        print(format_info(ident, status))
    return 0


def format_info(ident: IdentifyReply, status: StatusReport) -> str:
    rows = [
        (
            "firmware",
            f"{ident.firmware_version} on {ident.board_name}, protocol {ident.protocol_version}",
        ),
        ("axes", f"{ident.axis_count}"),
        (
            "tick",
            f"{ident.tick_hz} Hz, segments up to {ident.n_max} ticks, speeds in "
            f"1/{1 << ident.speed_shift} step/tick",
        ),
        (
            "queue",
            f"{status.queue_fill} of {ident.queue_capacity} slots in use"
            + (
                f"; laser rasters: a ring of {ident.raster_ring} powers"
                if ident.raster_ring
                else ""
            ),
        ),
        ("capabilities", ", ".join(ident.capability_names) or "none"),
        ("state", status.state.name + (f" (alarm {status.alarm.name})" if status.alarm else "")),
        ("next seq", f"{status.next_seq}"),
        ("segments done", f"{status.segments_done}"),
        ("motion ticks", f"{status.motion_ticks} ({status.motion_ticks / ident.tick_hz:.3f} s)"),
        ("positions", "  ".join(f"{AXIS_NAMES[i]} {p}" for i, p in enumerate(status.position))),
        ("counters", "  ".join(f"{name} {getattr(status, name)}" for name in COUNTERS)),
    ]
    width = max(len(name) for name, _ in rows)
    return "\n".join(f"{name:<{width}}  {value}" for name, value in rows)
