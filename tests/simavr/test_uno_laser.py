"""The Uno's laser build (`quadstep flash --board uno-laser`) in simavr: RASTER with a ring of 128
powers in the room of the cubic segments. The host reads the ring from IDENTIFY_REPLY, refuses a
configuration that needs cubic segments, and runs a grayscale raster through the real link as RASTER
lines, every step where it predicts it, from a plan or from a sender through the GRBL front door; the
stack keeps its margin."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import avr_scenarios
from avr_sim import F_CPU, Outputs, SimAvr, run_input
from grbl_client import GrblClient, report_fields
from grbl_door import serving
from laser_raster import raster_gcode, record_jobs
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.kernel.engine_model import predict
from quadstep.link import Link
from quadstep.machine import JobState, Machine, MachineError
from quadstep.planner.raster import RasterImage, plan_raster
from quadstep.protocol import Capability
from quadstep.protocol.raster import RasterLine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "laser-uno.toml")
BOARD = "uno-laser"


def with_jerk() -> object:
    axes = [axis.model_copy(update={"max_jerk": 20000.0}) for axis in CONFIG.axes]
    return CONFIG.model_copy(update={"axes": axes})


def test_a_raster_runs_on_the_uno_laser_build_as_predicted(avr_build: None, tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    image = RasterImage(rows=[[int(p) for p in rng.integers(0, 256, 120)] for _ in range(4)],
                        x_mm=10, y_mm=10, pixel_mm=0.1, row_mm=0.1, feed_mm_s=100)
    outputs = Outputs.in_dir(tmp_path, BOARD)
    with SimAvr(outputs, board=BOARD) as sim, Link.open(sim.url) as link:
        ident = link.identity
        assert ident is not None
        assert ident.capabilities & Capability.RASTER
        assert not ident.capabilities & (Capability.CUBIC_SEGMENTS | Capability.CUBIC_RUNS)
        assert (ident.raster_ring, ident.queue_capacity) == (128, 12)
        with pytest.raises(MachineError, match=r"axes\[0\].max_jerk = 20000.*no cubic"):
            Machine(link, with_jerk())  # type: ignore[arg-type]
        machine = Machine(link, CONFIG)
        plan = plan_raster(image, CONFIG, tuple(machine.position))
        before = dict(link.stats.as_dict())
        end = machine.run_job(plan).wait()
        after = link.stats.as_dict()
        machine.close()
    assert end is not None and end.ended_by == "done", end
    segments = list(plan.segments.segments())
    lines = [s for s in segments if isinstance(s, RasterLine)]
    assert sum(len(s.raster.power) for s in lines) >= 4 * 120 and all(len(s.raster.power) <= 128 for s in lines)
    assert after["starvations"] == before["starvations"]
    expected = predict(segments, list(plan.start), axis_count=3)
    assert np.array_equal(outputs.load_trace(), expected.steps)
    assert outputs.load_stats()["motion"]["ticks_missed"] == 0


@pytest.mark.parametrize("scenario", ["every_message_kind", "status_during_a_hold"])
def test_the_laser_build_keeps_its_stack_margin(scenario: str, avr_build: None, tmp_path: Path) -> None:
    """The deepest stacks of the Uno's own build (docs/AVR.md): the laser build's ring and its 12 slots
    leave at least the 80 bytes the Uno's build keeps above .data/.bss."""
    if scenario == "every_message_kind":
        stats = run_input(avr_scenarios.every_message_kind(3, cubic=False, pace=64), Outputs.in_dir(tmp_path), tmp_path / "r.bin",
                          board=BOARD)
    else:
        stats = run_input(avr_scenarios.status_during_a_hold(3), Outputs.in_dir(tmp_path), tmp_path / "r.bin",
                          board=BOARD, max_cycles=F_CPU // 2, until_idle=False)
    assert stats["motion"]["ticks_missed"] == 0 and stats["motion"]["steps"] != [0, 0, 0]
    stack = stats["stack"]
    assert stack["deepest"] - stack["static_end"] >= 80, stack


def test_a_sender_streams_a_raster_through_the_front_door_to_the_laser_build(avr_build: None,
                                                                             tmp_path: Path) -> None:
    """A LightBurn-style file (a `G1 X… S…` a pixel) through `quadstep grbl` by character counting, to the
    real laser build: its rows go out as RASTER lines that fit the ring of 128, every step as predicted."""
    lines = raster_gcode(rows=4, pixels=120)
    outputs = Outputs.in_dir(tmp_path, BOARD)
    with SimAvr(outputs, board=BOARD) as sim, Link.open(sim.url) as link:
        machine = Machine(link, CONFIG)
        jobs = record_jobs(machine)
        with serving(machine) as pty, GrblClient(str(pty.path)) as grbl:
            grbl.wait_banner()
            assert grbl.stream_counting(lines) == ["ok"] * len(lines)
            grbl.wait_status(lambda report: report_fields(report)["state"] == "Idle")
        end = tuple(link.status().position[:3])
        machine.close()
    file = tmp_path / "raster.nc"
    file.write_text("\n".join(lines) + "\n")
    assert end == load_job(file, CONFIG, (0, 0, 0)).plan.end
    assert all(job.state is JobState.DONE and job.states.starvations == 0 for job in jobs)
    sent = [segment for job in jobs for segment in job.plan.segments.segments()]
    assert sum(len(s.raster.power) for s in sent if isinstance(s, RasterLine)) >= 4 * 120
    assert np.array_equal(outputs.load_trace(), predict(sent, [0, 0, 0], axis_count=3).steps)
