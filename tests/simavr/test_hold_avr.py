"""HOLD on the real AVR firmware, running in simavr (tests/simavr's qs-simavr harness): the board's steps
around the hold tick, where it comes to rest and when, are exactly engine_model.predict_hold's."""

from __future__ import annotations

import json
import math
import random
import subprocess
from pathlib import Path

import pytest
from hold_helpers import check_hold, planned_job
from host_helpers import read_trace

from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.kernel.engine_model import predict_hold
from quadstep.machine.along_path import PathSpeeds, along_path
from quadstep.machine.units import hold_decels
from quadstep.protocol import (CubicSegment, Decoder, Event, Hold, HoldAlong, HoldDone, HoldDoneAlong, State,
                               StatusReport, encode)
from quadstep.kernel.fixed import DECEL_MAX

import avr_scenarios
import avr_sim

F_CPU = avr_sim.F_CPU
REPO = Path(__file__).resolve().parents[2]
ROUTER = load_config(REPO / "examples" / "router-uno.toml")
SCURVE = ROUTER.model_copy(update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in ROUTER.axes)})


def held_on_board(tmp_path: Path, board: str, axes: int, segments: list, hold: Hold | HoldAlong,
                  rng: random.Random, pause_bytes: tuple[int, int] = (2000, 4000)) -> tuple[Event, avr_sim.Outputs]:
    """`segments` queued, then `hold` mid-job, on the real firmware: its HOLD_DONE (checked to be the only
    event, after the one HOLDING answer) and the run's outputs."""
    # Empty frames (lone delimiters, ignored) keep the line busy ~20 µs each: the HOLD arrives mid-job.
    pause = b"\x00" * rng.randint(*pause_bytes)
    job = b"".join(encode(seg, seq) for seq, seg in enumerate(segments))
    (tmp_path / "input.bin").write_bytes(b"\x00" + job + pause + encode(hold, len(segments)))
    outputs = avr_sim.Outputs.in_dir(tmp_path, board)
    # Not --exit-when-idle: the harness would take HOLDING for rest; 1.5 s of board time is plenty.
    subprocess.run([*avr_sim.harness(board), "--input", str(tmp_path / "input.bin"),
                    "--output", str(tmp_path / "replies.bin"), "--max-cycles", str(3 * F_CPU // 2), *outputs.args()],
                   check=True, capture_output=True, timeout=120)
    replies = [item.message for item in Decoder("to_host", axis_count=axes).feed((tmp_path / "replies.bin").read_bytes())
               if hasattr(item, "message")]
    answers = [r for r in replies if isinstance(r, StatusReport)]
    events = [r for r in replies if isinstance(r, Event)]
    # HOLDING from the HOLD on: the motion runs on through the hold's window, the queue goes at its end
    assert len(answers) == 1 and answers[0].state == State.HOLDING and answers[0].queue_fill >= 1
    assert len(events) == 1, replies[-3:]
    return events[0], outputs


@pytest.mark.parametrize("board, axes, queue", [("uno", 3, 16), ("mega", 4, 32)])
def test_the_board_holds_exactly_as_predicted(avr_build: None, tmp_path: Path, board: str, axes: int,
                                              queue: int) -> None:
    rng = random.Random(board)
    segments = planned_job(rng, 8000, axis_count=axes)
    assert len(segments) <= queue  # all queued before the hold: the input has no flow control
    decels = [rng.randint(800, DECEL_MAX) for _ in range(axes)]
    hold = Hold(decel=tuple(decels + [0] * (4 - axes)))  # type: ignore[arg-type]
    done, outputs = held_on_board(tmp_path, board, axes, segments, hold, rng)
    assert type(done) is HoldDone
    pred = predict_hold(segments, done.hold_tick, decels + [1] * (4 - axes), axis_count=axes)
    assert pred.held is not None and 0 < done.hold_tick
    check_hold(outputs.trace, segments, done, decels + [1] * (4 - axes), axis_count=axes)
    stats = json.loads(outputs.stats.read_text())
    assert stats["motion"]["motion_ticks"] == done.motion_ticks
    assert stats["motion"]["state"] == State.IDLE
    rows = read_trace(outputs.trace)
    assert stats["motion"]["steps"] == [int((rows[:, 1] == axis).sum()) for axis in range(axes)]


@pytest.mark.parametrize("board, axes", [("uno", 3), ("mega", 4)])
@pytest.mark.parametrize("named", [True, False])
def test_hold_along_takes_the_path_decelerations_only_in_the_segments_it_names(
        avr_build: None, tmp_path: Path, board: str, axes: int, named: bool) -> None:
    """HOLD_ALONG naming every segment queued: its path's decelerations, and HOLD_DONE_ALONG; naming none of
    them: the HOLD's, and HOLD_DONE. The steps are predict_hold's with the decelerations taken."""
    rng = random.Random(f"{board} along")
    segments = planned_job(rng, 8000, axis_count=axes)
    assert len(segments) <= 16  # all queued before the hold (the Uno's queue)
    decels = [rng.randint(800, DECEL_MAX) for _ in range(axes)]
    path = [max(1, d // rng.randint(1, 5)) for d in decels]
    first, last = (0, len(segments) - 1) if named else (len(segments), 1000)
    hold = HoldAlong(decel=tuple(decels + [0] * (4 - axes)), path_decel=tuple(path + [0] * (4 - axes)),  # type: ignore[arg-type]
                     first=first, last=last)
    done, outputs = held_on_board(tmp_path, board, axes, segments, hold, rng)
    assert isinstance(done, HoldDone) and isinstance(done, HoldDoneAlong) == named
    taken = path if named else decels
    check_hold(outputs.trace, segments, done, taken + [1] * (4 - axes), axis_count=axes)


@pytest.mark.parametrize("along", [True, False])
def test_hold_along_in_s_curve_segments_stops_on_the_line(avr_build: None, tmp_path: Path, along: bool) -> None:
    """A 3:1 diagonal planned as S-curves, held at full speed on the Uno: with the decelerations the host
    works out from the firmware's chain (machine/along_path.py), the board takes them in its cubic segments
    and rests on the line; with each axis's own, about 120 steps off it."""
    config = SCURVE
    path = tmp_path / "diagonal.gcode"
    path.write_text("G21 G90 F2400\nG1 X30 Y10\n")
    segments = list(load_job(path, config).plan.segments.segments())
    assert len(segments) <= 14 and any(isinstance(s, CubicSegment) for s in segments)  # all queued
    speeds = PathSpeeds(3)
    speeds.sent(0, segments, 0)
    own = hold_decels(config)
    run = along_path(speeds.reader(Listed(segments), 0), 4, len(segments), 4, own)  # held in the cruise
    assert run is not None and run.last == len(segments) - 1
    hold = HoldAlong(decel=(*own, 0), path_decel=(*run.decels, 0), first=0 if along else len(segments),
                     last=run.last if along else 1000)
    # 0.3 to 0.4 s of the line's time: the cruise (the ramp up takes 0.1 s)
    done, outputs = held_on_board(tmp_path, "uno", 3, segments, hold, random.Random(f"{along}"), (15000, 20000))
    assert isinstance(done, HoldDoneAlong) == along
    corner = config.to_steps((30.0, 10.0, 0.0))
    assert 1000 < done.position[0] < corner[0] - 1000  # held on the way, well before the end
    off = abs(done.position[0] * corner[1] - done.position[1] * corner[0]) / math.hypot(corner[0], corner[1])
    assert off <= 1.0 if along else off > 50
    rows = read_trace(outputs.trace)
    assert tuple(int(rows[rows[:, 1] == axis, 2].sum()) for axis in range(3)) == tuple(done.position)


class Listed:
    def __init__(self, items: list) -> None:
        self.items = items

    def segment(self, i: int):  # noqa: ANN201
        return self.items[i]


@pytest.mark.parametrize("tick_hz", [32_000, 40_000])
def test_holds_at_thirty_two_moments_lose_no_timer_period(avr_build: None, tmp_path: Path, tick_hz: int) -> None:
    """HOLDs at 16 phases of the tick during a 300-tick segment, three axes near full speed (the rescale
    multiplies: the costliest hold to begin), behind jobs of 15 and of 10 segments (the HOLDs fall at other
    moments of the segments in each), on the Uno's default 32 kHz and on a 40 kHz build. The lock only
    opens the hold's window; the tick plans the hold, works out the increments it will begin with, and
    begins it (rescaling the positions alone) in later ticks of the window, each within two timer periods,
    even at 40 kHz (800 cycles), and never in the tick that loads a segment: not one period is lost (exact
    cycles). Every HOLD reaches the board (its status answers it)."""
    elf = avr_sim.elf_path("uno")
    if tick_hz != avr_sim.avr_define("QS_TICK_HZ"):
        build = tmp_path / "build"
        subprocess.run(["make", "-C", str(avr_sim.REPO), "-s", "firmware", f"BUILD={build}",
                        f"AVR_TICK_HZ={tick_hz}"], capture_output=True, check=True)
        elf = build / "avr" / "uno.elf"
    lock = isr = lost = 0
    for segments in (15, 10):
        for pad in range(0, 200, 13):  # the HOLD arrives at a different phase of the tick each time
            (tmp_path / "hold.input").write_bytes(avr_scenarios.hold_from_full_speed(3, pad, segments))
            outputs = avr_sim.Outputs.in_dir(tmp_path, f"hold{segments}-{pad}")
            replies = tmp_path / f"hold{segments}-{pad}.replies"
            subprocess.run([*avr_sim.harness("uno", elf), "--input", str(tmp_path / "hold.input"),
                            "--output", str(replies), "--max-cycles", str(F_CPU // 4), *outputs.args()],
                           check=True, capture_output=True, timeout=120)
            assert avr_scenarios.hold_answered(replies.read_bytes(), 3), (segments, pad)
            stats = json.loads(outputs.stats.read_text())
            assert stats["tick_cycles"] == F_CPU // tick_hz
            assert stats["motion"]["state"] == State.HOLDING  # decelerating when the run ends
            lock = max(lock, stats["irq_off"]["max"])
            isr = max(isr, stats["isr"]["timer"]["max"])
            lost += stats["motion"]["ticks_missed"]
    assert lost == 0
    # was 555 (the hold begun under the lock) and 418, with 5 periods lost; then 843, the tick that began
    # the hold (the rescale of h and of the increments), which lost 16 periods at 40 kHz; then 852, the
    # tick that loaded a segment and worked out the increments for it (a HOLD whose beginning fell in a
    # segment begun in its window), which lost one at 40 kHz; now the longest is the tick that plans the
    # hold or the one that works out the increments (773 at 32 kHz with a HOLD, 766 with the HOLD_ALONG a
    # motion sends: the main loop's few more cycles move where the HOLD falls in the tick; 765 once the link
    # relaxed its calls)
    assert (lock, isr) == (200, {32_000: 765, 40_000: 765}[tick_hz])
