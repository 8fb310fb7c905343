"""A long open job lets go of what the board has run (machine/rebase.py): its plan, stream, take-ups
and program begin again at a move boundary the board is past, so that memory stays bounded however
long the stream. What is sent is unchanged: the emulator's trace is the prediction of every stream
in turn, each reversal has its take-up, and the job ends on its last target."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from backlash_helpers import backlash_config, pushed_plus, write_sim
from host_helpers import assert_trace_is_prediction
from machine_helpers import read_trace_with_carriage
from rolling_legs import ROW_MOVES, WhatRan, rows, run_in_parts
from waiting import wait_until

from quadstep.gcode.interpreter import parse_gcode
from quadstep.kernel.cubic_chain import CubicChain
from quadstep.kernel.engine_model import predict
from quadstep.link import Link
from quadstep.machine import JobState, Machine
from quadstep.machine import job as job_module
from quadstep.machine import rebase as rebase_module
from quadstep.machine.rebase import entry_chain, find, rebased
from quadstep.machine.restream import MachineRestream
from quadstep.machine.takeups import StreamPlan, TakeUps
from quadstep.planner.plan import plan_program
from quadstep.planner.program import Program

CONFIG = backlash_config((0.1, 0.05, 0.0))
BACKLASH_STEPS = (40.0, 20.0, 0.0)


def zigzag(count: int) -> str:
    """Moves of 0.25 mm along X, each up or down 0.25 mm in Y: Y reverses at every move."""
    return "G21 G90 F2400\n" + "".join(
        f"G1 X{0.25 * k:.2f} Y{10 + 0.25 * (k % 2):.2f}\n" for k in range(1, count)
    )


def parse(text: str):
    return parse_gcode(text, CONFIG.axis_names, (0.0, 0.0, 0.0), CONFIG.arc_tolerance)


def whole_stream(count: int, path=rows) -> tuple[Program, StreamPlan, np.ndarray]:
    """`count` rows (or moves of another `path`) planned and compensated whole, from rest with the
    band not known yet; its cumulative ticks."""
    program = parse(path(count))
    plan = plan_program(program, CONFIG, (0, 0, 0))
    compensated = TakeUps(CONFIG).compensate(plan.segments, plan.pauses)
    whole = StreamPlan(CONFIG, compensated.stream, compensated.pauses, compensated, plan)
    return program, whole, np.concatenate([[0], np.cumsum(whole.segments.numpy()["n"])])


def test_a_rebased_stream_is_the_rest_of_the_stream_with_its_band(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _, whole, ticks = whole_stream(12)
    plan, compensated = whole.base, whole.compensated
    upto = len(whole) // 2
    assert find(whole, ticks, upto) is None  # too little run yet to let go of
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 10)
    at = find(whole, ticks, upto)
    assert at is not None and 10 <= at.index <= upto
    kept = rebased(whole, at)
    assert isinstance(kept, StreamPlan)
    # every item from there on, as it was; none before
    assert list(kept.segments.segments()) == list(whole.segments.segments(at.index))
    assert kept.base.moves == plan.moves - at.moves
    assert list(kept.base.move_ends) == [e - at.segment for e in plan.move_ends[at.moves :]]
    assert kept.base.end == plan.end
    # the steppers where it begins as planned, and the motors there: the take-ups before it too
    planned = predict(list(plan.segments.segments(0, at.segment)), axis_count=3).positions
    assert kept.base.start == tuple(planned)
    made = predict(list(whole.segments.segments(0, at.index)), axis_count=3).positions
    assert tuple(made) == at.motor
    assert at.motor != kept.base.start  # take-ups were made before it
    # the firmware's chain there, as the whole stream leaves it
    chain = CubicChain(3)
    predict(list(whole.segments.segments(0, at.index)), axis_count=3, chain=chain)
    assert kept.compensated.entry == entry_chain(whole, at.index) == chain
    assert any(axis.e for axis in chain.axes)  # a residual to carry
    # the band, from there on, as the whole stream's
    for tick in range(at.ticks, int(ticks[-1]), 997):
        assert kept.compensated.band_at(tick - at.ticks) == compensated.band_at(tick)
    assert len(kept.compensated.takeups) == sum(t.start >= at.ticks for t in compensated.takeups)
    assert kept.compensated.band_end == compensated.band_end


def test_the_machine_follows_the_band_through_a_rebased_stream_as_through_the_whole(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Its record of the running take-ups moves on by the rebase's ticks and steps: the band at any
    later tick, and after a stop there, is the one the whole stream gives."""
    _, whole, ticks = whole_stream(12)
    compensated = whole.compensated
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 10)
    at = find(whole, ticks, 2 * len(whole) // 3)
    assert at is not None
    kept = rebased(whole, at)
    assert isinstance(kept, StreamPlan)
    whole_record, rebased_record = TakeUps(CONFIG), TakeUps(CONFIG)
    motor, tick = (5, -7, 0), 1000  # where and when the stream began
    whole_record.begin(compensated, motor, tick)
    rebased_record.begin(compensated, motor, tick)
    rebased_record.swap(kept.compensated, at.ticks, at.motor)
    steps = predict(list(whole.segments.segments()), axis_count=3).steps
    changed = 0
    for stop in range(at.ticks + 1, int(ticks[-1]), 1511):
        made = steps[steps[:, 0] <= stop]
        here = [m + int(made[made[:, 1] == a, 2].sum()) for a, m in enumerate(motor)]
        shown = whole_record.position(here, tick + stop)
        assert rebased_record.position(here, tick + stop) == shown
        changed += shown != whole_record.position(here, tick + stop - at.ticks)
    assert changed  # a record not moved on would show other positions
    # a stop inside a take-up: the band follows the motors from where the take-up began
    window = kept.compensated.windows[-1]
    stop = at.ticks + window.start + window.ticks // 2
    made = steps[steps[:, 0] <= stop]
    here = [m + int(made[made[:, 1] == a, 2].sum()) for a, m in enumerate(motor)]
    whole_record.end(here, tick + stop, False)
    rebased_record.end(here, tick + stop, False)
    assert rebased_record.band == whole_record.band
    assert whole_record.band.axes[0].w not in (0, whole_record.band.axes[0].size)  # inside it


def test_where_every_move_reverses_an_axis_the_plan_begins_again_inside_a_move(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Y's take-up lies across every move boundary of a zigzag: the plan begins again inside a move,
    after the take-up, with the rest of that move as its move 0."""
    _, whole, ticks = whole_stream(120, zigzag)
    plan = whole.base
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 10)
    at = find(whole, ticks, len(whole) // 2)
    assert at is not None and at.segment not in plan.move_ends
    kept = rebased(whole, at)
    assert isinstance(kept, StreamPlan)
    assert list(kept.segments.segments()) == list(whole.segments.segments(at.index))
    assert kept.base.move_ends[0] == plan.move_ends[at.moves] - at.segment  # the rest of its move
    assert kept.base.moves == plan.moves - at.moves
    planned = predict(list(plan.segments.segments(0, at.segment)), axis_count=3).positions
    assert kept.base.start == tuple(planned)
    chain = CubicChain(3)
    made = predict(list(whole.segments.segments(0, at.index)), axis_count=3, chain=chain)
    assert tuple(made.positions) == at.motor
    assert kept.compensated.entry == chain  # moving there: the axes' speeds carried too
    assert any(axis.i for axis in chain.axes)


@pytest.mark.realtime
@pytest.mark.parametrize("path, count", [(rows, 30), (zigzag, 320)], ids=["rows", "zigzag"])
def test_a_long_open_job_lets_go_of_what_ran_and_sends_the_same(
    start_emulator, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, path, count: int
) -> None:
    """Given 21 lines at a time, 4 rows' worth ahead of the machine: rows whose X reverses at each
    row's end, and a zigzag whose Y reverses at every move (the job begins again inside moves)."""
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 80)
    ran = WhatRan(monkeypatch)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(trace=trace, axes=3, tick_hz=CONFIG.tick_hz, queue=14)
    whole = parse(path(count))
    head = 1 + 5 * (ROW_MOVES + 1)  # five rows, then a row at a time, 4 rows ahead of the machine
    run, longest = run_in_parts(emu.url, CONFIG, whole, head, ROW_MOVES + 1, 4 * ROW_MOVES)
    emu.stop()
    sent = ran.sent
    assert ran.rebases >= 3  # it let go of what ran, several times
    assert longest < len(sent)  # and kept less than that
    assert run.plan.compensated.takeups  # the reversals after it still have their take-ups
    assert run.progress.done == run.progress.total == len(sent) + len(run.plan)
    sent.extend(run.plan.segments.segments())
    # what the board ran is every stream in turn (where the board never ran dry, braking by itself)
    if JobState.STARVED not in run.states.history:
        assert_trace_is_prediction(trace, sent, axis_count=3)


@pytest.mark.realtime
def test_a_feed_hold_after_the_job_let_go_of_what_ran_goes_on_to_its_last_target(
    start_emulator, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The hold's rest, its band and the rest of the job are found in what the job kept."""
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 80)
    rebases: list[int] = []
    let_go = job_module.rebased

    def counted(plan, at):
        rebases.append(at.index)
        return let_go(plan, at)

    monkeypatch.setattr(job_module, "rebased", counted)
    rests: list[tuple[int, ...]] = []  # the positions the machine takes at the hold's rest
    held = MachineRestream.held

    def held_here(restream: MachineRestream, end):
        rests.append(held(restream, end))
        return rests[-1]

    monkeypatch.setattr(MachineRestream, "held", held_here)
    sim = write_sim(tmp_path / "sim.toml", BACKLASH_STEPS)  # carriages behind their motors
    trace = tmp_path / "trace.csv"
    emu = start_emulator(
        axes=3, tick_hz=CONFIG.tick_hz, queue=14, trace=trace, extra_args=["--machine", str(sim)]
    )
    whole = parse(rows(16))
    head = 1 + 5 * (ROW_MOVES + 1)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        machine.takeups.reset(pushed_plus(CONFIG))  # as the simulated machine's carriages are
        program = parse(rows(5))
        run = machine.run_job(plan_program(program, CONFIG, (0, 0, 0)), program, open_end=True)
        held_at = None
        for given in range(head, len(whole.items), ROW_MOVES + 1):
            wait_until(lambda: run.progress.line >= given - 4 * ROW_MOVES)
            if len(rebases) >= 2 and held_at is None:
                assert run.feed_hold()
                wait_until(lambda: run.held)
                made = read_trace_with_carriage(trace)  # at rest: written out
                held_at = [made[made[:, 1] == axis][-1, 4] for axis in (0, 1)]
                assert run.resume()
            items = whole.items[given : given + ROW_MOVES + 1]
            assert run.extend(items, items[-1].line)
        run.close()
        end = run.wait(120)
        assert end is not None and end.ended_by == "done", end
        assert held_at is not None and JobState.HELD in run.states.history
        # the band where the hold left it, found in the stream the job kept: the positions there
        # are the carriages' (half their band behind, as they began)
        assert len(rests) == 1 and len(rebases) >= 2
        assert list(rests[0][:2]) == [c + b / 2 for c, b in zip(held_at, BACKLASH_STEPS)]
        planned = plan_program(whole, CONFIG, (0, 0, 0)).end
        assert machine.position == planned
    carriages = [axis["carriage"] for axis in emu.stop()["machine"]["axes"]]
    # every take-up made where it was due, none twice: the carriages are exactly where the job put
    # them (half their band behind the positions, as they began)
    assert carriages == [p - b / 2 for p, b in zip(planned, BACKLASH_STEPS)]


def test_a_rebased_plan_keeps_the_outputs_in_force_and_the_pauses_to_come(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """What the board runs under where the plan begins again is its first OUTPUTS (a feed hold may
    stop the spindle and switch it on again); the pauses and OUTPUTS after it move with it."""
    plain = backlash_config((0.0, 0.0, 0.0))
    text = rows(6).replace("F2400\n", "F2400\nM3 S1000\n", 1) + "M0\nM5\n" + rows(2)[14:]
    program = parse_gcode(text, plain.axis_names, (0.0, 0.0, 0.0), plain.arc_tolerance)
    plan = plan_program(program, plain, (0, 0, 0))
    (pause, _), = plan.pauses
    assert [section for _, section, _ in plan.outputs] == [0, 1]  # M3, then M5 after the M0
    ticks = np.concatenate([[0], np.cumsum(plan.segments.numpy()["n"])])
    monkeypatch.setattr(rebase_module, "REBASE_SEGMENTS", 10)
    at = find(plan, ticks, pause // 2)
    assert at is not None and at.index < pause
    kept = rebased(plan, at)
    assert kept.pauses == [(pause - at.index, plan.pauses[0][1])]
    assert kept.outputs == [
        (0, 0, plan.outputs[0][2]),
        (plan.outputs[1][0] - at.index, 1, plan.outputs[1][2]),
    ]
    assert kept.segments.numpy()["n"].tolist() == plan.segments.numpy()["n"][at.index :].tolist()
    assert list(kept.move_ends) == [e - at.segment for e in plan.move_ends[at.moves :]]
