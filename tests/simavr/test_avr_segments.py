"""SEGMENTS and CUBIC_SEGMENTS on the board: the same streams sent as chained records, several to a frame
(PROTOCOL.md §5.2), make
exactly the steps of the emulator and of the host's prediction on the real AVR firmware in simavr, and take
far fewer bytes than one SEGMENT a frame."""

from __future__ import annotations

from pathlib import Path

import pytest

import avr_scenarios
from quadstep.link import Link
from quadstep.protocol import Capability, Segment, StatusReport, encode
from quadstep.protocol.cubic_run import CubicSegments
from quadstep.protocol.messages import queue_slots
from quadstep.protocol.frames import next_frame, run_limit
from quadstep.protocol.segment_run import RunChain, Segments
from test_avr_steps import AXES, run_both


class _Run:
    def __init__(self, segments: list[Segment]) -> None:
        self.segments = segments

    def segment(self, i: int) -> Segment:
        return self.segments[i]


def frames(run: list[Segment], limit: int) -> list:
    """The run as a motion sends it: SEGMENTS once the chain is known."""
    chain, out, index = RunChain(4), [], 0
    while index < len(run):
        message = next_frame(_Run(run), index, len(run), chain, limit)
        out.append(message)
        index += queue_slots(message)
    return out


def send_packed(url: str, runs: list[list[Segment]]) -> StatusReport:
    with Link.open(url) as link:
        status = link.status()
        identity = link.identity
        assert identity is not None and identity.capabilities & Capability.SEGMENTS
        for run in runs:
            sent = frames(run, run_limit(identity.queue_capacity))
            assert any(isinstance(m, (Segments, CubicSegments)) and len(m) > 1 for m in sent)
            for message in sent:
                link.send(message, timeout=60)
            status = link.wait_idle(timeout=120)
    return status


@pytest.mark.parametrize("name", ["ramps_and_reversals", "random_runs", "quadratic_into_cubic"])
def test_uno_runs_sent_as_segments_match_emulator_and_model(name: str, avr_build: None, tmp_path: Path,
                                                            start_emulator) -> None:  # noqa: ANN001
    axes = AXES["uno"]
    runs = {
        "ramps_and_reversals": lambda: avr_scenarios.ramps_and_reversals(axes),
        "random_runs": lambda: avr_scenarios.random_runs(axes, seed=7),
        "quadratic_into_cubic": lambda: avr_scenarios.quadratic_into_cubic(axes),
    }[name]()
    run_both("uno", runs, tmp_path, start_emulator, send=send_packed)
    plain = sum(len(encode(s, 0)) for run in runs for s in run)
    packed = sum(len(encode(m, 0)) for run in runs for m in frames(run, run_limit(14)))
    assert packed < plain


def test_mega_runs_sent_as_segments_match_emulator_and_model(avr_build: None, tmp_path: Path,
                                                             start_emulator) -> None:  # noqa: ANN001
    run_both("mega", avr_scenarios.random_runs(AXES["mega"], seed=11, runs=2), tmp_path, start_emulator,
             send=send_packed)
