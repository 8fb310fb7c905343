"""RASTER on the real Mega build and the Uno's laser build in simavr (the Uno's own build has no room
for it: capability bit 14 clear): the lines are taken, the steps are the host's prediction, and the
laser's PWM shows each pixel's power, in the order the axis crosses them, while the axis is over it."""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import numpy as np
import pytest

from avr_sim import Outputs, harness
from quadstep.kernel.engine_model import predict
from quadstep.protocol import Output, Outputs as OutputsMessage, Segment, encode
from quadstep.kernel.motion import AxisMove
from quadstep.protocol.raster import Raster, RasterLine

PERIOD = 64 * 256  # cycles per PWM period
V = 2048  # half a step a tick: a pixel of 50 steps lasts 100 ticks, 4 ms at the Mega's 25 kHz, about 4 periods
AXES = {"mega": 4, "uno-laser": 3}
POWERS = [[30, 200, 90, 250, 10], [120, 5, 220, 60, 180]]


def line(powers: list[int]) -> RasterLine:
    """1,000 ticks at V (250 steps), five pixels of 50 steps, the first one from the start."""
    raster = Raster(n=1000, axes=0x01, pixel=0, phase=50 * 256, pitch=50 * 256, power=tuple(powers))
    return RasterLine(n=1000, axes=(AxisMove(axis=0, direction=1, v0=V, vn=V, r=0),), raster=raster)


@pytest.fixture(scope="module", params=sorted(AXES))
def run(avr_build: None, tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest
        ) -> tuple[dict, list, list]:
    board = request.param
    ramp_up = Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=0, vn=V, r=0),))
    ramp_down = Segment(n=200, axes=(AxisMove(axis=0, direction=1, v0=V, vn=0, r=0),))
    lines = [line(p) for p in POWERS]
    messages = [
        OutputsMessage(outputs=Output.ON, power=0),
        ramp_up,
        *(x.raster for x in lines),
        ramp_down,
        OutputsMessage(outputs=0, power=0),
        Segment(n=500, axes=()),
    ]
    frames = b"".join(encode(m, i) for i, m in enumerate(messages))
    directory = tmp_path_factory.mktemp("raster")
    outputs = Outputs.in_dir(directory)
    pins = directory / "pins.csv"
    feed = outputs.stats.with_suffix(".feed")
    feed.write_bytes(frames)
    args = [
        *harness(board),
        "--feed",
        str(feed),
        "--max-cycles",
        str(2 * 16_000_000),
        "--outputs",
        str(pins),
        *outputs.args(),
    ]
    result = subprocess.run(args, capture_output=True, timeout=120)
    assert result.returncode == 0, result.stderr.decode(errors="replace")
    with pins.open() as f:
        edges = [(int(r["cycle"]), r["pin"], int(r["level"])) for r in csv.DictReader(f)]
    segments = [ramp_up, *lines, ramp_down, Segment(n=500, axes=())]
    return outputs.load_stats(), edges, [outputs.load_trace(), segments, AXES[board]]


def test_the_board_takes_raster_lines_and_steps_as_predicted(run) -> None:
    stats, _, (trace, segments, axis_count) = run
    feed = stats["feed"]
    assert feed["accepted"] == feed["frames"] == 7 and feed["alarms"] == feed["errors"] == 0, feed
    assert stats["motion"]["ticks_missed"] == 0, stats["motion"]
    expected = predict(segments, [0] * axis_count, axis_count=axis_count)
    assert np.array_equal(trace, expected.steps)


def test_the_pwm_shows_every_pixel_in_order(run) -> None:
    _, edges, _ = run
    pulses, rise = [], None
    for cycle, name, level in edges:
        if name != "pwm":
            continue
        if level:
            rise = cycle
        elif rise is not None:
            pulses.append((rise, cycle))
            rise = None
    # the pulses on the timer's grid: simavr takes a new OCR at once, not at the period's end as the chip
    # does, which can add a pulse off the grid (test_avr_outputs.py)
    first = pulses[0][0]
    highs = [
        f - r
        for r, f in pulses
        if min((r - first) % PERIOD, PERIOD - (r - first) % PERIOD) <= 3 and f - r < PERIOD
    ]
    # a high stretch of (duty byte + 1) / 256 of a period; the byte is the pixel's power
    seen = [round(h * 256 / PERIOD) - 1 for h in highs]
    order = [p for i, p in enumerate(seen) if i == 0 or abs(p - seen[i - 1]) > 1]
    pixels = [p for row in POWERS for p in row]
    assert [p for p in order if p > 2] == [p for p in pixels if p > 2], (order, pixels)
