"""`quadstep raster IMAGE`: an image becomes G-code rows that `quadstep run` finds again as
rasters, every pixel's power where the image has it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from quadstep.cli import main
from quadstep.cli._jobs import format_duration
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.planner.raster_gcode import find_runs, plan_with_rasters
from quadstep.protocol.raster import RasterLine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "laser-uno.toml")


def gradient(path: Path, width: int, height: int) -> list[list[int]]:
    levels = [[(17 * x + 40 * y) % 256 for x in range(width)] for y in range(height)]
    image = Image.new("L", (width, height))
    image.putdata([v for row in levels for v in row])
    image.save(path)
    return levels


def test_an_image_becomes_rows_the_planner_finds_again(tmp_path: Path) -> None:
    levels = gradient(tmp_path / "in.png", 40, 5)
    job_file = tmp_path / "out.nc"
    assert (
        main(
            [
                "raster",
                str(tmp_path / "in.png"),
                "-o",
                str(job_file),
                "--origin",
                "10",
                "20",
                "--feed",
                "6000",
            ]
        )
        == 0
    )
    job = load_job(job_file, CONFIG, (0, 0, 0))
    runs = find_runs(job.program, CONFIG, (0.0, 0.0, 0.0))
    assert len(runs) == 5
    for number, run in enumerate(runs):
        row = levels[len(levels) - 1 - number]  # the bottom row first
        lit = [k for k, v in enumerate(row) if v < 255]
        expected = [
            round(CONFIG.spindle.power(round(1000 * (255 - v) / 255, 1)) / 257) for v in row
        ]
        widths = [round(abs(b - a) / 0.1) for a, b in zip(run.row.edges_mm, run.row.edges_mm[1:])]
        powers = [p for p, w in zip(run.row.powers, widths) for _ in range(w)]
        if number % 2:
            powers.reverse()
        assert powers == expected[lit[0] : lit[-1] + 1]
        assert run.row.at_mm[1] == pytest.approx(20 + 0.1 * number)
    plan = plan_with_rasters(job.program, CONFIG, (0, 0, 0))
    assert plan is not None
    assert sum(isinstance(s, RasterLine) for s in plan.segments.segments()) >= 5


def test_a_file_that_is_not_an_image_is_one_clear_error(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "not.png"
    bad.write_text("hello")
    assert main(["raster", str(bad)]) != 0
    err = capsys.readouterr().err
    assert "not.png" in err and "image" in err


def test_run_reports_the_plan_the_machine_runs_its_rasters_in(
    start_emulator, tmp_path: Path, capsys
) -> None:
    """`quadstep run` of a raster job on a board with RASTER: the segments and the planned time it
    reports (and its progress follows) are those of the RASTER rows it sends, not of one move a
    pixel."""
    gradient(tmp_path / "in.png", 60, 4)
    job_file = tmp_path / "out.nc"
    raster = ["raster", str(tmp_path / "in.png"), "-o", str(job_file), "--origin", "10", "20"]
    assert main([*raster, "--feed", "3000"]) == 0
    capsys.readouterr()
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    config = str(REPO / "examples" / "laser-uno.toml")
    assert main(["run", str(job_file), "--config", config, "--port", emu.url, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    job = load_job(job_file, CONFIG, (0, 0, 0))
    rows = plan_with_rasters(job.program, CONFIG, (0, 0, 0))
    assert rows is not None and len(rows) < len(job.plan) / 4
    assert summary["completed"] and summary["exact"]
    assert summary["segments"] == len(rows)
    assert summary["planned_duration_s"] == pytest.approx(rows.duration_s)
    assert summary["motion_ticks"] == rows.duration_ticks


def test_check_and_run_say_the_time_of_the_rows_before_the_job_runs(start_emulator, tmp_path: Path, capsys) -> None:
    """Rows at one speed each, ramped outside the image, take longer than one move a pixel would: `check` says
    what a board with RASTER runs, and `run`'s first line the plan it runs, not the moves'."""
    gradient(tmp_path / "in.png", 60, 4)
    job_file = tmp_path / "out.nc"
    assert main(["raster", str(tmp_path / "in.png"), "-o", str(job_file), "--origin", "10", "20"]) == 0
    job = load_job(job_file, CONFIG, (0, 0, 0))
    rows = plan_with_rasters(job.program, CONFIG, (0, 0, 0))
    assert rows is not None and rows.duration_s > 1.5 * job.plan.duration_s
    config = str(REPO / "examples" / "laser-uno.toml")
    capsys.readouterr()
    assert main(["check", str(job_file), "--config", config]) == 0
    said = capsys.readouterr().out.splitlines()
    assert f"distance {job.summary().distance_mm:.1f} mm, planned duration {format_duration(job.plan.duration_s)}" in said
    assert (f"on a board with RASTER (the Mega, the emulator, the Uno's laser build), its laser rasters as rows at "
            f"one speed each: {len(rows)} segments, planned duration {format_duration(rows.duration_s)}") in said
    emu = start_emulator(free=True, axes=3, tick_hz=CONFIG.tick_hz)
    assert main(["run", str(job_file), "--config", config, "--port", emu.url]) == 0
    first, done = capsys.readouterr().out.splitlines()[:2]
    assert first == (f"{job_file}: {job.source_size}, {job.plan.moves} moves, {len(rows)} segments, "
                     f"{format_duration(rows.duration_s)} planned; every target inside the travel")
    assert done.endswith(f"{len(rows)} segments, {format_duration(rows.duration_s)} of motion"), done
