"""A host that ignores flow control floods the board while it steps: bytes
the firmware cannot hold are lost, but never silently. Every frame that lost bytes is refused with RX_OVERRUN, and the
steps made are exactly those of the segments the firmware accepted.

The firmware takes segments faster than a 500000 baud line brings them, so
the flood mixes in STATUS requests: each answer is longer than the request
and the segment that came with it, the transmitter (one byte per tick) falls
behind, and the main loop, waiting for room to send, leaves the receive ring
to fill."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import avr_scenarios
from avr_sim import Outputs, run_input
from quadstep.kernel.engine_model import predict, predict_underrun
from quadstep.protocol import Ack, AckReason, Decoder, ErrorCode, ErrorReport, Identify, Status, encode
from quadstep.kernel.fixed import D


def test_flood_loses_bytes_loudly_and_runs_only_accepted_segments(avr_build: None, tmp_path: Path) -> None:
    builder = avr_scenarios.ChainBuilder(3)
    segments = [builder.segment(300, {0: (1, D // 2, D // 2)}) for _ in range(59)]
    segments.append(builder.segment(300, {0: (1, D // 2, 0)}))
    status = encode(Status(), 0)
    data = b"\x00" + encode(Identify(), 0) + b"".join(encode(s, i) + status for i, s in enumerate(segments))

    outputs = Outputs.in_dir(tmp_path)
    stats = run_input(data, outputs, tmp_path / "replies.bin", max_cycles=16_000_000)
    replies = [f.message for f in Decoder("to_host", axis_count=3).feed((tmp_path / "replies.bin").read_bytes())]

    overruns = [m for m in replies if isinstance(m, ErrorReport) and m.code == ErrorCode.RX_OVERRUN]
    assert overruns, "a flood this size must overflow the receive ring"
    # Lost in the firmware's ring, which it reports; never in the USART
    # itself, which the tick empties in time.
    assert stats["wire"]["lost"] == 0

    accepted = [m for m in replies if isinstance(m, Ack) and m.reason == AckReason.ACCEPTED]
    seqs = [a.next_seq - 1 for a in accepted]
    assert len(seqs) >= 2 and seqs == list(range(len(seqs))), "segments are accepted in order, each once"
    # The last accepted segment ends moving: the underrun's controlled stop follows it (stop deceleration 256).
    accepted_segments = segments[: len(seqs)]
    stop = predict_underrun(accepted_segments, [256] * 3, axis_count=3)
    moved = predict(accepted_segments, axis_count=3).steps
    expected = np.concatenate([moved, stop.steps])
    trace = outputs.load_trace()  # the run ends (max_cycles) before the stop is at rest
    assert len(moved) < len(trace) <= len(expected)
    assert np.array_equal(trace, expected[: len(trace)])
