"""GRBL's override bytes through the front door on the real emulator: the feed override (0x90–0x94)
re-plans the running batch on the way and the job still ends on its exact steps; rapid (0x95–0x97)
and spindle (0x99–0x9D) overrides are in the status report's Ov: and in what is planned next (a
slower rapid, a scaled S), the targets untouched."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving
from host_helpers import read_trace

from quadstep.config import load_config
from quadstep.gcode.interpreter import parse_gcode
from quadstep.kernel.engine_model import predict
from quadstep.link import Link
from quadstep.machine import JobRun, JobState, Machine
from quadstep.machine.speed_overrides import SpeedOverrides
from quadstep.planner.feed_override import Overrides, apply_overrides
from quadstep.planner.plan import plan_program
from quadstep.protocol import Output

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
STEPS_PER_MM = round(CONFIG.axes[0].steps_per_mm)  # X's
CONFIG_S = CONFIG.model_copy(
    update={"spindle": CONFIG.spindle.model_copy(update={"s_max": 10000.0})}
)


@pytest.fixture
def door(start_emulator) -> Iterator[tuple[Machine, GrblClient]]:
    """The emulator ticking in real time, so that a batch is still running when a byte arrives."""
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, free=False)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                yield machine, grbl


def ov(report: str) -> str | None:
    return report_fields(report).get("Ov")


def test_the_feed_override_replans_the_running_batch_and_it_ends_exactly(
    door: tuple[Machine, GrblClient],
) -> None:
    machine, grbl = door
    # moves of 2 mm: boundaries ahead where the rest is planned again
    lines = ["G1 X2 F600", *(f"X{x}" for x in range(4, 41, 2))]
    assert grbl.stream_counting(lines) == ["ok"] * len(lines)
    grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
    job = machine.program
    assert isinstance(job, JobRun)
    planned = job.plan
    for byte in (0x91, 0x91, 0x91, 0x93, 0x94, 0x91, 0x91):  # +10 ×3, +1, −1, +10 ×2: 150 %
        grbl.realtime(byte)
    report = grbl.wait_status(lambda r: ov(r) is not None and ov(r) != "100,100,100")
    assert ov(report) == "150,100,100"
    running = grbl.wait_status(lambda r: r.startswith("<Run") and job.feed_override == 150)
    assert report_fields(running)["FS"].startswith("900,")
    done = grbl.wait_status(lambda r: r.startswith("<Idle"))
    assert job.plan is not planned  # the rest was planned again at 150 %, moving
    assert mpos(done) == (40.0, 0.0, 0.0)
    assert tuple(machine.link.status().position[:3]) == CONFIG.to_steps((40.0, 0.0, 0.0))
    grbl.realtime(0x90)
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,100,100"
    for _ in range(25):
        grbl.realtime(0x92)  # −10 % each, held at 10 %
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "10,100,100"


def test_rapid_and_spindle_overrides_are_reported_and_planned_next(
    door: tuple[Machine, GrblClient],
) -> None:
    machine, grbl = door
    grbl.realtime(0x97)  # rapids at 25 %
    for byte in (0x9A, 0x9A, 0x9D):  # spindle +10 +10 −1: 119 %
        grbl.realtime(byte)
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,25,119"
    assert machine.speed_overrides.rapid == 25 and machine.speed_overrides.spindle == 119
    assert grbl.command("G0 X5 Y2")[1] == "ok"
    assert mpos(grbl.wait_status(lambda r: r.startswith("<Idle"))) == (5.0, 2.0, 0.0)
    grbl.realtime(0x18)  # a soft reset: every override back to 100 %
    grbl.wait_banner()
    assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,100,100"


def test_a_rapid_at_25_percent_takes_longer_and_ends_on_the_same_steps() -> None:
    program = parse_gcode("G0 X100 Y20\nG1 X90 F600\nG0 X0 Y0\n", CONFIG.axis_names)
    overrides = SpeedOverrides()
    full = plan_program(overrides.apply(program, CONFIG, (0, 0, 0)), CONFIG)
    overrides.set_rapid(25)
    slow = plan_program(overrides.apply(program, CONFIG, (0, 0, 0)), CONFIG)
    assert slow.end == full.end == (0, 0, 0)
    assert slow.move_ends.tolist() != [] and len(slow.move_ends) == len(full.move_ends)
    ticks = sum(int(n) for n in full.segments.n), sum(int(n) for n in slow.segments.n)
    assert ticks[1] > 3 * ticks[0]  # the feed move is the same; the rapids four times as long


def test_the_spindle_override_scales_the_s_sent() -> None:
    program = parse_gcode("M3 S5000\nG1 X10 F600\nM5\n", CONFIG_S.axis_names)
    overrides = SpeedOverrides()
    overrides.set_spindle(150)
    plan = plan_program(overrides.apply(program, CONFIG_S, (0, 0, 0)), CONFIG_S)
    powers = [message.power for _, _, message in plan.outputs]
    assert powers[0] == CONFIG_S.spindle.power(7500) and powers[-1] == 0
    with pytest.raises(ValueError, match="outside 10–200"):
        overrides.set_spindle(201)
    with pytest.raises(ValueError, match="25, 50, 100"):
        overrides.set_rapid(75)


def test_coolant_toggles_at_rest(door: tuple[Machine, GrblClient]) -> None:
    _, grbl = door
    grbl.realtime(0xA0)  # flood on
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M5 M8 T0 F0 S0]"]
    assert "|A:F" in grbl.wait_status(lambda r: ov(r) is not None)
    grbl.realtime(0xA1)  # mist on
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M5 M7 M8 T0 F0 S0]"]
    assert grbl.command("M3 S100")[1] == "ok"  # a line keeps them
    grbl.wait_status(lambda r: r.startswith("<Idle"))
    report = grbl.wait_status(lambda r: ov(r) is not None)
    assert report.endswith("|A:SFM>")
    grbl.realtime(0xA0)
    grbl.realtime(0xA1)
    assert grbl.command("$G")[0] == ["[GC:G0 G54 G17 G21 G90 G94 M3 M9 T0 F0 S100]"]


def rapids(steps: np.ndarray) -> tuple[int, int]:
    """Of a step trace whose X goes to 20 mm and on in rapids: the ticks from the step that reaches
    X20 to the last one, and the fewest ticks any millimetre of the rapids took (their top speed)."""
    x = steps[steps[:, 1] == 0]
    position = np.cumsum(x[:, 2])
    ticks = x[int(np.argmax(position == 20 * STEPS_PER_MM)) :, 0]
    return int(ticks[-1] - ticks[0]), int((ticks[STEPS_PER_MM:] - ticks[:-STEPS_PER_MM]).min())


def test_rapid_and_spindle_overrides_reach_the_running_batch(start_emulator, tmp_path: Path) -> None:
    """0x97 and 0x9A while a sender's stream runs: the rapids not yet sent run at a quarter of their
    speed and the spindle's duty goes to 150 % from a move boundary on; the job ends on its steps."""
    config = CONFIG.model_copy(
        update={"spindle": CONFIG.spindle.model_copy(update={"s_max": 1000.0})}
    )
    outputs, trace = tmp_path / "outputs.csv", tmp_path / "trace.csv"
    emu = start_emulator(
        axes=3,
        tick_hz=config.tick_hz,
        free=False,
        trace=trace,
        extra_args=["--outputs", str(outputs)],
    )
    lines = ["M3 S500", "G1 X2 F600", *(f"X{x}" for x in range(4, 21, 2)), "G0 X60", "G0 X0", "M5"]
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        with serving(machine) as pty, GrblClient(str(pty.path)) as grbl:
            grbl.wait_banner()
            assert grbl.stream_counting(lines) == ["ok"] * len(lines)
            grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
            job = machine.program
            assert isinstance(job, JobRun)
            grbl.realtime(0x97)  # rapids at 25 %
            for _ in range(5):
                grbl.realtime(0x9A)  # spindle +10 % ×5: 150 %
            assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "100,25,150"
            done = grbl.wait_status(lambda r: r.startswith("<Idle"), timeout=60)
            assert mpos(done) == (0.0, 0.0, 0.0)
            assert tuple(link.status().position[:3]) == (0, 0, 0)
    emu.stop()
    # the rapids as the board ran them, against the same moves planned at 100 % and at 25 %
    program = parse_gcode("G1 X20 F600\nG0 X60\nG0 X0\n", config.axis_names, (0.0, 0.0, 0.0))
    slow = apply_overrides(program, Overrides(rapid=25), config, (0, 0, 0))
    full, quarter = (
        rapids(predict(list(plan_program(p, config).segments.segments()), axis_count=3).steps)
        for p in (program, slow)
    )
    ran = rapids(read_trace(trace))
    assert ran[1] >= 0.99 * quarter[1] and ran[1] > 3 * full[1]  # never faster than 25 %
    if JobState.STARVED in job.states.history:  # a busy computer: a stop on the way, no faster
        assert ran[0] >= 0.99 * quarter[0]
    else:
        assert ran[0] == pytest.approx(quarter[0], rel=0.01)
    assert ran[0] > 3 * full[0]
    rows = [line.split(",") for line in outputs.read_text().splitlines()[1:]]
    changes = [(int(pins), int(duty)) for _, pins, duty in rows]
    # each byte reaches the job: the duty steps up from 50 % to 75 % (some steps may be passed by,
    # taken over by the next before they were sent), and is off at the end
    assert changes[0] == (1, round(65535 * 0.5)) and changes[-2:] == [(1, round(65535 * 0.75)), (0, 0)]
    middle = [duty for pins, duty in changes[1:-1]]
    assert all(pins == 1 for pins, _ in changes[1:-1]) and middle == sorted(middle)


def test_spindle_stop_during_a_feed_hold_and_back_on_resume(start_emulator, tmp_path: Path) -> None:
    """0x9E is ignored while the batch runs; during a feed hold it turns the spindle off (the
    coolant kept) and cycle start brings it back as the job had it; the job ends exactly."""
    config = CONFIG.model_copy(
        update={"spindle": CONFIG.spindle.model_copy(update={"s_max": 1000.0})}
    )
    outputs = tmp_path / "outputs.csv"
    emu = start_emulator(
        axes=3, tick_hz=config.tick_hz, free=False, extra_args=["--outputs", str(outputs)]
    )
    lines = ["M8 M3 S500", "G1 X2 F600", *(f"X{x}" for x in range(4, 21, 2))]
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        with serving(machine) as pty, GrblClient(str(pty.path)) as grbl:
            grbl.wait_banner()
            assert grbl.stream_counting(lines) == ["ok"] * len(lines)
            grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
            grbl.realtime(0x9E)  # running: ignored
            grbl.realtime(ord("!"))
            held = grbl.wait_status(lambda r: r.startswith("<Hold:0") and "|A:" in r)
            assert report_fields(held)["A"] == "SF"
            grbl.realtime(0x9E)
            stopped = grbl.wait_status(lambda r: "|A:" in r)
            assert report_fields(stopped)["A"] == "F"  # the spindle off, the flood kept
            grbl.realtime(ord("~"))
            assert grbl.command("M5 M9")[1] == "ok"
            done = grbl.wait_status(lambda r: r.startswith("<Idle"), timeout=60)
            assert mpos(done) == (20.0, 0.0, 0.0)
            assert tuple(link.status().position[:3]) == config.to_steps((20.0, 0.0, 0.0))
    emu.stop()
    rows = [line.split(",") for line in outputs.read_text().splitlines()[1:]]
    on, flood = int(Output.ON | Output.FLOOD), int(Output.FLOOD)
    half = round(65535 * 0.5)
    assert [(int(pins), int(duty)) for _, pins, duty in rows] == [
        (on, half),  # M3 M8
        (flood, 0),  # 0x9E in the hold
        (on, half),  # resumed
        (0, 0),  # M5 M9
    ]


@pytest.mark.realtime
def test_the_feed_override_replans_a_running_s_curve_batch(start_emulator) -> None:
    """max_jerk set: the running batch's rest is planned again with the S-curve planner from a move
    boundary, moving, and the job still ends on its exact steps."""
    config = CONFIG.model_copy(
        update={"axes": tuple(a.model_copy(update={"max_jerk": 20000.0}) for a in CONFIG.axes)}
    )
    emu = start_emulator(axes=3, tick_hz=config.tick_hz, free=False)
    lines = ["G1 X2 F600", *(f"X{x} Y{x % 4 // 2}" for x in range(4, 31, 2))]
    with Link.open(emu.url) as link:
        machine = Machine(link, config)
        with serving(machine) as pty, GrblClient(str(pty.path)) as grbl:
            grbl.wait_banner()
            assert grbl.stream_counting(lines) == ["ok"] * len(lines)
            grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
            job = machine.program
            assert isinstance(job, JobRun)
            planned = job.plan
            for _ in range(5):
                grbl.realtime(0x91)  # +10 % ×5: 150 %
            assert ov(grbl.wait_status(lambda r: ov(r) is not None)) == "150,100,100"
            done = grbl.wait_status(lambda r: r.startswith("<Idle"), timeout=60)
            assert job.plan is not planned and job.feed_override == 150
            assert mpos(done) == (30.0, 1.0, 0.0)
            assert tuple(link.status().position[:3]) == config.to_steps((30.0, 1.0, 0.0))
            assert job.progress.starvations == 0
