#!/usr/bin/env python3
"""Host-side figures: codec speed, wire bytes per segment, link throughput to the emulator.

    python3 tests/bench/bench_host.py [--segments N]

Prints figures only; nothing here is a pass/fail test.
"""

from __future__ import annotations

import argparse
import random
import time

from quadstep.emulator import Emulator
from quadstep.link import Link
from quadstep.protocol import Ack, AckReason, Decoder, Segment, encode
from quadstep.kernel.fixed import D
from quadstep.kernel.motion import AxisMove


def three_axis_segments(count: int, seed: int = 1) -> list[Segment]:
    rng = random.Random(seed)
    out = []
    for i in range(count):
        last = i == count - 1
        out.append(Segment(n=rng.randint(20, 200), axes=tuple(
            AxisMove(axis=a, direction=rng.choice([1, -1]), v0=rng.randint(0, D),
                     vn=0 if last else rng.randint(0, D), r=rng.randint(-D, D - 1))
            for a in range(3)
        )))
    return out


def rate(count: int, seconds: float) -> str:
    return f"{count / seconds:,.0f}/s"


def bench_codec(segments: list[Segment]) -> None:
    start = time.perf_counter()
    frames = [encode(seg, i & 0xFF) for i, seg in enumerate(segments)]
    encode_s = time.perf_counter() - start
    stream = b"".join(frames)
    start = time.perf_counter()
    decoded = Decoder("to_firmware").feed(stream)
    decode_s = time.perf_counter() - start
    assert len(decoded) == len(segments)
    acks = b"".join(encode(Ack(next_seq=i & 0xFF, free=5, reason=AckReason.ACCEPTED, done=i & 0xFFFF), i & 0xFF)
                    for i in range(len(segments)))
    start = time.perf_counter()
    Decoder("to_host").feed(acks)
    ack_s = time.perf_counter() - start
    print(f"encode 3-axis SEGMENT       {rate(len(segments), encode_s)} frames (= segments)")
    print(f"decode 3-axis SEGMENT       {rate(len(segments), decode_s)} frames (streaming, with validation)")
    print(f"decode ACK                  {rate(len(segments), ack_s)} frames")


def bench_wire() -> None:
    seg = three_axis_segments(1)[0]
    frame = encode(seg, 7)
    ack = encode(Ack(next_seq=8, free=3, reason=AckReason.ACCEPTED, done=1), 7)
    print(f"wire bytes, 3-axis segment  {len(frame)} (body 23, crc 2, COBS 1, delimiter 1)")
    print(f"wire bytes back per segment {len(ack)} ACK + at most {len(ack)} SPACE ack "
          f"(one SPACE ack may cover several segments) = {2 * len(ack)} at most")
    for baud in (115_200, 250_000, 500_000, 1_000_000):
        print(f"  at {baud:>9,} baud (10 bits/byte): {baud / 10 / len(frame):,.0f} segments/s line limit")


def bench_link(segments: list[Segment]) -> None:
    with Emulator(free=True) as emu, Link.open(emu.url) as link:
        start = time.perf_counter()
        for seg in segments:
            link.send(seg)
        status = link.wait_idle(timeout=600)
        seconds = time.perf_counter() - start
        stats = link.stats
    print(f"link to free emulator       {rate(len(segments), seconds)} segments "
          f"({len(segments)} in {seconds:.2f} s, {status.motion_ticks:,} ticks executed, "
          f"{stats.retransmits} retransmits, {stats.bytes_sent / len(segments):.1f} bytes sent per segment)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=20_000)
    args = parser.parse_args()
    segments = three_axis_segments(args.segments)
    print("== host codec and link ==")
    bench_codec(segments)
    bench_wire()
    bench_link(segments)


if __name__ == "__main__":
    main()
