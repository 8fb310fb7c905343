"""A job's path as written: rapids and cuts told apart, its bounding box in work and machine coordinates
(`quadstep check`), and the path in `quadstep plot`'s figure and in the TUI's braille view."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from quadstep.cli import main
from quadstep.config import load_config
from quadstep.job import load_job
from quadstep.toolpath import toolpath
from quadstep.tui.canvas import Canvas

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
JOB = "G10 L2 P1 X10 Y5\nG54\nG0 X0 Y0\nG1 X20 Y10 F600\nG1 Y0\nG0 Z-5\nG0 X0\n"


def test_rapids_and_cuts_and_the_boxes(tmp_path: Path) -> None:
    job_file = tmp_path / "offset.gcode"
    job_file.write_text(JOB)
    config = load_config(ROUTER)
    job = load_job(job_file, config)
    path = toolpath(job.program, (0.0, 0.0, 0.0))
    assert [p.rapid for p in path.pieces] == [True, False, False, True, True]
    assert (path.rapids, path.cuts) == (3, 2)
    assert path.pieces[0].start == (0.0, 0.0, 0.0) and path.pieces[0].end == (10.0, 5.0, 0.0)
    assert path.machine_box is not None and path.work_box is not None
    assert path.machine_box.low == (0.0, 0.0, -5.0) and path.machine_box.high == (30.0, 15.0, 0.0)
    assert path.work_box.low == (0.0, 0.0, -5.0) and path.work_box.high == (20.0, 10.0, 0.0)


def test_check_prints_the_bounding_box_in_both_coordinates(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    job_file = tmp_path / "offset.gcode"
    job_file.write_text(JOB)
    assert main(["check", str(job_file), "--config", str(ROUTER)]) == 0
    out = capsys.readouterr().out
    assert "bounding box   work     X 0.000 … 20.000  Y 0.000 … 10.000  Z -5.000 … 0.000" in out
    assert "               machine  X 0.000 … 30.000  Y 0.000 … 15.000  Z -5.000 … 0.000" in out
    assert "2 cuts, 3 rapids" in out
    assert main(["check", str(job_file), "--config", str(ROUTER), "--json"]) == 0
    bounds = json.loads(capsys.readouterr().out)["bounds"]
    assert bounds["machine"]["X"] == [0.0, 30.0] and bounds["work"]["Y"] == [0.0, 10.0]


def test_plot_draws_rapids_and_cuts_apart(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    job_file = tmp_path / "offset.gcode"
    job_file.write_text(JOB)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures: list[object] = []
    close = plt.close
    plt.close = lambda fig=None: figures.append(fig)  # type: ignore[assignment]  # keep the figure to read it
    try:
        assert main(["plot", str(job_file), "--config", str(ROUTER), "-o", str(tmp_path / "p.png")]) == 0
    finally:
        plt.close = close  # type: ignore[assignment]
    assert (tmp_path / "p.png").stat().st_size > 0
    path_axes = figures[0].axes[2]  # type: ignore[attr-defined]
    styles = {line.get_label(): line.get_linestyle() for line in path_axes.get_lines()}
    assert styles == {"rapid (G0)": "--", "cut": "-"}
    assert path_axes.get_title() == "path: 2 cuts, 3 rapids"


def test_the_braille_canvas_layers_and_marks() -> None:
    canvas = Canvas(4, 2)
    low, high = canvas.layer("blue"), canvas.layer("red")
    canvas.line(0, 0, 7, 0, low)
    canvas.line(0, 7, 7, 7, high, every=2)
    canvas.mark(7, 4, "●", high)
    rows = canvas.render().plain.split("\n")
    assert rows[0] == "⠉⠉⠉⠉"  # a solid line through the top dots of each cell
    assert rows[1] == "⡀⡀⡀●"  # every other dot (the left bottom one of each cell); the mark takes its cell
