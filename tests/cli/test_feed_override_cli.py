"""`quadstep run --feed-override PERCENT`: every feed of the job at that share (rapids not), exactly as predicted;
outside 10–200 % refused before anything is sent."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from host_helpers import assert_trace_is_prediction

from quadstep.cli import main
from quadstep.config import load_config
from quadstep.job import load_job

REPO = Path(__file__).resolve().parents[2]
ROUTER = REPO / "examples" / "router-uno.toml"
CONFIG = load_config(ROUTER)
JOB = "G21 G90\nG1 X20 F600\nG0 X0\n"


def test_a_job_runs_at_the_feed_override_given(start_emulator, tmp_path: Path, capsys) -> None:  # noqa: ANN001
    job = tmp_path / "line.gcode"
    job.write_text(JOB)
    trace = tmp_path / "trace.csv"
    emu = start_emulator(free=True, trace=trace, axes=3, tick_hz=CONFIG.tick_hz)
    code = main(["run", str(job), "--config", str(ROUTER), "--port", emu.url, "--json", "--feed-override", "150"])
    out, err = capsys.readouterr()
    assert code == 0, err
    result = json.loads(out)
    emu.stop()
    at_150, at_100 = load_job(job, CONFIG, feed_override=150).plan, load_job(job, CONFIG).plan
    assert result["completed"] and result["motion_ticks"] == at_150.duration_ticks
    assert_trace_is_prediction(trace, at_150.segments.segments(), axis_count=3, min_steps=1000)
    # the G1 takes two thirds of its time at 100 % (less the ramps); the rapid back is the same
    feed_ticks = [at.move_ends[0] for at in (at_150, at_100)]
    g1 = [int(np.sum(p.segments.numpy()["n"][:e])) for p, e in zip((at_150, at_100), feed_ticks)]
    assert g1[0] < g1[1] * 0.7
    rapid = [p.duration_ticks - t for p, t in zip((at_150, at_100), g1)]
    assert rapid[0] == rapid[1]


@pytest.mark.parametrize("value", ["5", "201", "abc"])
def test_a_feed_override_outside_the_bounds_is_refused(value: str, tmp_path: Path, capsys) -> None:  # noqa: ANN001
    job = tmp_path / "line.gcode"
    job.write_text(JOB)
    with pytest.raises(SystemExit) as exit_:
        main(["run", str(job), "--config", str(ROUTER), "--emulator", "--feed-override", value])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "--feed-override" in err
    assert ("outside 10–200 %" in err) if value != "abc" else ("not a whole number" in err)
