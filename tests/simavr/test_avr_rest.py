"""The step tick at rest, in exact simulated cycles. With nothing queued, no hold and no input
being debounced, a resting tick (Timer1's compare B, step_timer.c) stands in for the whole one:
23 cycles a tick on the Uno, under 5 % of the CPU, and the main loop sleeps on through it. A
debounce in progress runs the whole tick every tick, as before: 343 cycles a tick with the
inputs' rare path, 69 % of the CPU while the window is open."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import avr_scenarios
from avr_sim import F_CPU, REPO, Outputs, avr_define, elf_path, harness, run_feed
from quadstep.kernel.engine_model import predict
from quadstep.kernel.fixed import D
from quadstep.protocol import Config, Input, encode

REST_CYCLES = 23  # the resting tick, interrupt entry and exit included
REST_SHARE_GOAL = 0.05  # of the CPU, with nothing queued
DEBOUNCE = 200  # ticks
RELEASE_AT = 20_000  # sample ticks: cycle start, pressed at power-up, is released then


def whole_tick_entry() -> int:
    """The address of the whole tick's first instruction (`push r1`, 2 cycles)."""
    listing = subprocess.run(["avr-objdump", "-d", str(elf_path("uno"))], capture_output=True,
                             text=True, check=True).stdout
    line = listing[listing.index("<__vector_11>:"):].splitlines()[1]
    assert "push\tr1" in line
    return int(line.split(":")[0], 16)


def run_at_rest(tmp_path: Path, debounce: int | None = None) -> dict:
    """One simulated second of the Uno with nothing queued; with `debounce`, a CONFIG giving
    every input that many ticks and a button released mid-run. Returns the stats, with the
    whole ticks run (from the profile) and the step interrupt's cycles."""
    frames = b""
    args = []
    if debounce is not None:
        config = Config(invert=0, enabled=0x0FFF, hard_limits=0, debounce=(debounce,) * 12,
                        hold_decel=(3000, 3000, 3000, 0))
        frames = encode(config, 0)
        machine = tmp_path / "machine.toml"
        machine.write_text(
            f'[[press]]\ninput = "cycle_start"\nat_tick = 0\nticks = {RELEASE_AT}\n')
        args = ["--machine", str(machine)]
    (tmp_path / "in.bin").write_bytes(frames)
    outputs = Outputs.in_dir(tmp_path)
    profile = tmp_path / "profile.csv"
    result = subprocess.run(
        [*harness("uno"), "--input", str(tmp_path / "in.bin"),
         "--output", str(tmp_path / "out.bin"), "--max-cycles", str(F_CPU),
         "--profile-pc", str(profile), *args, *outputs.args()],
        capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    stats = outputs.load_stats()
    rows = (row.split(",") for row in profile.read_text().splitlines()[1:])
    cycles = {int(address, 16): int(count) for address, _, count in rows}
    stats["whole_ticks"] = cycles[whole_tick_entry()] // 2
    stats["isr_cycles"] = stats["isr"]["timer"]["total"]
    return stats


@pytest.fixture(scope="module")
def quiet(avr_build: None, tmp_path_factory: pytest.TempPathFactory) -> dict:
    return run_at_rest(tmp_path_factory.mktemp("quiet"))


def test_with_nothing_queued_the_tick_rests_at_23_cycles(quiet: dict) -> None:
    timer = quiet["isr"]["timer"]
    assert timer["count"] > 31_900  # every tick of the second is served ...
    assert quiet["motion"]["ticks_missed"] == 0 and quiet["motion"]["tick_late_max"] <= 8
    assert timer["min"] == REST_CYCLES
    assert quiet["whole_ticks"] == 1  # ... by the resting tick, after the first
    assert quiet["isr_cycles"] <= REST_SHARE_GOAL * F_CPU
    assert quiet["isr_cycles"] == 735_629, quiet["isr"]


def test_with_nothing_queued_the_main_loop_sleeps_on(quiet: dict) -> None:
    """A resting tick wakes the main loop too: it sleeps on after a few tests unless a whole tick
    ran or the outputs' period came round. Tick and main loop together are awake under a tenth
    of the time (about half before)."""
    awake = quiet["cycles"] - quiet["sleep_cycles"]
    assert awake <= 0.10 * quiet["cycles"], awake
    assert awake - quiet["isr_cycles"] <= 0.055 * quiet["cycles"], awake


def test_a_debounce_in_progress_runs_the_whole_tick_every_tick(avr_build: None,
                                                               tmp_path: Path) -> None:
    """The button's release opens a window of DEBOUNCE ticks, each a whole tick; then the tick
    rests again. The same run with no debounce takes the release at once, in one whole tick."""
    (tmp_path / "at_once").mkdir()
    (tmp_path / "debounced").mkdir()
    at_once = run_at_rest(tmp_path / "at_once", debounce=0)
    debounced = run_at_rest(tmp_path / "debounced", debounce=DEBOUNCE)
    for stats in (at_once, debounced):
        edges = stats["input_edges"]
        assert [(e["input"], e["level"]) for e in edges][-1:] == [(Input.CYCLE_START, 1)], edges
        assert stats["motion"]["ticks_missed"] == 0
        # CONFIG holds the tick off for less than a tick (675 cycles once: a tick lost by chance)
        assert stats["irq_off"]["max"] < stats["tick_cycles"], stats["irq_off"]
    assert debounced["whole_ticks"] - at_once["whole_ticks"] == DEBOUNCE - 1
    # each of those ticks: the whole tick and the inputs' rare path (the window's count)
    per_tick = REST_CYCLES + (debounced["isr_cycles"] - at_once["isr_cycles"]) / (DEBOUNCE - 1)
    assert round(per_tick) == 343, per_tick  # 345 before the link relaxed its calls


def test_where_a_tick_lasts_two_byte_times_the_tick_does_not_rest(avr_build: None,
                                                                  tmp_path: Path) -> None:
    """The Mega's default, 25 kHz at 500000 baud: a tick is 640 cycles, two byte times. The
    resting tick looks for a byte once a tick and the receiver holds two, so a byte that came
    just after a look could be lost as the third (a stream on a 25 kHz Uno once lost its first
    frame's byte). There every tick is a whole one, with its two looks."""
    (tmp_path / "in.bin").write_bytes(b"")
    outputs = Outputs.in_dir(tmp_path)
    result = subprocess.run(
        [*harness("mega"), "--input", str(tmp_path / "in.bin"), "--output", str(tmp_path / "out.bin"),
         "--max-cycles", str(F_CPU // 10), *outputs.args()], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    stats = outputs.load_stats()
    timer = stats["isr"]["timer"]
    assert stats["tick_cycles"] == 640 == 2 * F_CPU * 10 // avr_define("QS_BAUD", "mega")
    assert timer["count"] > 2_400  # every tick of the tenth of a second ...
    assert timer["min"] > 4 * REST_CYCLES, timer  # ... a whole one


WAKE_TICK_HZ = 40_000  # a rate at which the main loop's report after a stream can fall on a match


def stream(count: int) -> list:
    """A dwell, then `count` segments of 256 ticks, three axes stepping every tick (Y backwards)."""
    b = avr_scenarios.ChainBuilder(3)
    dirs = {0: 1, 1: -1, 2: 1}
    segments = [avr_scenarios.dwell()]
    segments += [b.segment(256, {a: (dirs[a], D, D) for a in range(3)}) for _ in range(count - 1)]
    segments.append(b.segment(256, {a: (dirs[a], D, 0) for a in range(3)}))
    return segments


def test_a_wake_from_rest_as_a_match_falls_due_loses_no_tick(avr_build: None,
                                                             tmp_path: Path) -> None:
    """A byte to send, or a segment queued, ends the rest (step_timer_wake): it looks at the timer's
    flags and clears the stale one. A match between the look and the clear would lose its tick.
    Streams of several lengths end at rest, and the board's last reports wake the tick at
    different moments of it; on the Uno built for 40 kHz, the stream of 16 segments wakes it
    on the match (the wake's look once cleared that match's own flag there: a tick lost)."""
    build = tmp_path / "build"
    subprocess.run(["make", "-C", str(REPO), "-s", "firmware", f"BUILD={build}",
                    f"AVR_TICK_HZ={WAKE_TICK_HZ}"], capture_output=True, check=True)
    for count in range(8, 25):
        segments = stream(count)
        frames = b"".join(encode(s, i) for i, s in enumerate(segments))
        outputs = Outputs.in_dir(tmp_path, f"n{count}")
        stats = run_feed(frames, outputs, elf=build / "avr" / "uno.elf", max_cycles=F_CPU // 3)
        assert stats["tick_cycles"] == F_CPU // WAKE_TICK_HZ
        assert stats["feed"]["accepted"] == len(segments), (count, stats["feed"])
        motion = stats["motion"]
        assert motion["ticks_missed"] == 0, (count, motion)
        assert motion["tick_late_max"] <= stats["tick_cycles"] // 4, (count, motion)
        assert np.array_equal(outputs.load_trace(), predict(segments, axis_count=3).steps), count
