"""The spindle/laser and coolant pins of the real firmware in simavr (Uno): the PWM on D11 at GRBL's 976.6 Hz
with the duty the OUTPUTS message asks for, exact in cycles; direction on D13 and coolant on A3/A4; a laser
power that follows the speed through a ramp, each PWM period within the main loop's sampling of the exact
level (qs_outputs_level); everything off again after the last message."""

from __future__ import annotations

import csv
import math
import subprocess
from pathlib import Path

import pytest

from avr_sim import Outputs, harness
from quadstep.protocol import Output, Outputs as OutputsMessage, Segment, encode
from quadstep.kernel.motion import AxisMove

PERIOD = 64 * 256  # cycles per PWM period: clock / 64, 8-bit fast PWM
TICK = 500  # cycles per motion tick at the Uno's 32 kHz
RAMP_N, RAMP_V = 1000, 3000  # a ramp of axis 0 from rest to 3000/4096 step per tick, and back
POWER, REFERENCE = 60000, 4000
# simavr moves a pin when the instruction running at the timer's match ends: an edge comes up to 3 cycles late
# (call, ret and reti take 4), so a pulse is within 3 cycles of its exact length.
EDGE_SLACK = 3
SAMPLE_SLACK = 12  # ticks: the ramp's start from its first step, and a frame's work before the main loop samples


def ratio(num: int, den: int) -> int:
    """The firmware's qs_outputs_ratio."""
    while den > 0xFFFF:
        den >>= 1
        num >>= 1
    return 0x10000 if num >= den else (num << 16) // den


def ramp_duty(t: int) -> int:
    """The exact dynamic duty after t ticks of the ramp up (2n·v(t) against 2n·speed)."""
    return POWER * ratio(2 * RAMP_V * t, 2 * RAMP_N * REFERENCE) >> 16


@pytest.fixture(scope="module")
def run(avr_build: None, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, list[tuple[int, str, int]], list]:
    messages = [
        OutputsMessage(outputs=Output.ON | Output.REVERSE | Output.FLOOD, power=0x8000),
        Segment(n=1000, axes=()),  # a dwell with the spindle at half power
        Segment(n=1000, axes=()),
        OutputsMessage(outputs=Output.ON | Output.DYNAMIC | Output.MIST, power=POWER, axis=0, speed=REFERENCE),
        Segment(n=RAMP_N, axes=(AxisMove(axis=0, direction=1, v0=0, vn=RAMP_V, r=0),)),
        Segment(n=RAMP_N, axes=(AxisMove(axis=0, direction=1, v0=RAMP_V, vn=0, r=0),)),
        OutputsMessage(outputs=0, power=0),
        Segment(n=1000, axes=()),
    ]
    frames = b"".join(encode(m, i) for i, m in enumerate(messages))
    directory = tmp_path_factory.mktemp("outputs")
    outputs = Outputs.in_dir(directory)
    pins = directory / "pins.csv"
    stats = _run(frames, outputs, pins)
    with pins.open() as f:
        edges = [(int(r["cycle"]), r["pin"], int(r["level"])) for r in csv.DictReader(f)]
    return stats, edges, outputs.load_edges()


def _run(frames: bytes, outputs: Outputs, pins: Path) -> dict:
    """The frames fed as fast as flow control allows, free-running, with the output pins recorded."""
    feed = outputs.stats.with_suffix(".feed")
    feed.write_bytes(frames)
    args = [*harness("uno"), "--feed", str(feed), "--max-cycles", str(3 * 16_000_000), "--outputs", str(pins),
            *outputs.args()]
    result = subprocess.run(args, capture_output=True, timeout=120)
    assert result.returncode == 0, result.stderr.decode(errors="replace")
    return outputs.load_stats()


def highs(edges: list[tuple[int, str, int]], pin: str) -> list[tuple[int, int]]:
    """(rise, fall) cycles of every high stretch of `pin`."""
    out, rise = [], None
    for cycle, name, level in edges:
        if name != pin:
            continue
        if level:
            rise = cycle
        elif rise is not None:
            out.append((rise, cycle))
            rise = None
    return out


def periods(edges: list[tuple[int, str, int]]) -> list[tuple[int, int]]:
    """The PWM's periods: (rise, fall) of the pulses that begin on the timer's grid (clock / 64 / 256 from the
    first one, within EDGE_SLACK). simavr applies a new OCR2A at once instead of at the period's
    end as the chip does, which can add a pulse off the grid; those are left out."""
    pulses = highs(edges, "pwm")
    first = pulses[0][0]
    return [(r, f) for r, f in pulses if min((r - first) % PERIOD, PERIOD - (r - first) % PERIOD) <= EDGE_SLACK]


def test_constant_power_is_the_duty_asked_for_exact_in_cycles(run: tuple) -> None:
    stats, edges, _ = run
    assert stats["feed"]["accepted"] == 8, stats["feed"]
    # OCR2A = 0x80: high 129/256 of each whole period of the 2000-tick dwell (each edge within EDGE_SLACK)
    dwell_end = highs(edges, "flood")[0][1]
    half = [(r, f) for r, f in periods(edges) if abs(f - r - 129 * 64) <= EDGE_SLACK and f < dwell_end]
    assert len(half) >= 58, f"{len(half)} periods at half power: {[f - r for r, f in periods(edges)[:10]]}"
    span = half[-1][0] - half[0][0]
    assert abs(span - (len(half) - 1) * PERIOD) <= EDGE_SLACK, "one period after the other, clock / 64 / 256"


def test_direction_and_coolant_follow_the_message(run: tuple) -> None:
    _, edges, _ = run
    direction, flood, mist = highs(edges, "direction"), highs(edges, "flood"), highs(edges, "mist")
    assert len(direction) == 1 and len(flood) == 1 and len(mist) == 1, (direction, flood, mist)
    # the reversed spindle with flood until the laser message, then mist until everything goes off
    assert abs(direction[0][1] - flood[0][1]) < PERIOD + 10 and mist[0][0] >= flood[0][1] - PERIOD
    pwm = highs(edges, "pwm")
    assert pwm[-1][1] <= mist[0][1] + PERIOD, "the PWM stops with the last message"


def test_laser_power_follows_the_ramp(run: tuple) -> None:
    """Each period's duty is the exact level (qs_outputs_level) at a moment within a period of it: the main loop
    samples the level once per period, after the overflow (as soon as the frame it may be reading is done); the
    chip applies the new OCR2A at the next period, simavr at once, so the sample is of the period before or of
    this one."""
    _, edges, steps = run
    start = _ramp_start(steps)
    # whole periods inside the ramp up (simavr applies a new OCR2A at once, not at the period's end as the chip
    # does, so the period in which the ramp begins is left out)
    ramp = [(r, f) for r, f in periods(edges) if start + PERIOD <= r <= start + RAMP_N * TICK - PERIOD]
    assert len(ramp) >= 25, len(ramp)
    checked = 0
    for rise, fall in ramp:
        ocr = (fall - rise) // 64 - 1
        # the ramp's start is known to a few ticks, and the main loop takes its sample after the overflow once it
        # is done with what it was doing: a frame's work, up to about 5,000 cycles (10 ticks)
        t_lo = max(0, (rise - PERIOD - start) // TICK - SAMPLE_SLACK)
        t_hi = min(RAMP_N, (rise + PERIOD - start) // TICK + SAMPLE_SLACK)
        if t_hi <= 0:
            continue
        low, high = ramp_duty(t_lo) >> 8, ramp_duty(t_hi) >> 8
        assert low <= ocr <= high, f"period at cycle {rise}: OCR {ocr}, exact level between {low} and {high}"
        checked += 1
    assert checked >= 25


def _ramp_start(steps: list) -> int:
    """The cycle of the ramp's tick 0, from its first step: the first step of a ramp from rest at v(t) =
    a·t comes at the tick where a·t²/2 reaches half a step."""
    first_step = min(c for c, pin, axis, level in steps if pin == "step" and level)
    a = RAMP_V / RAMP_N / 4096  # steps per tick²
    t_first = math.ceil(math.sqrt(1.0 / a))  # x(t) = a t²/2 ≥ ½
    return first_step - t_first * TICK
