"""The rapid and spindle override keys (r, < >): the machine's overrides, shown on the machine panel's
state line; while a job runs they reach what it has not yet sent (its rest planned again), and it still
ends exactly on its last target."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from host_helpers import read_trace
from quadstep.config import MachineConfig
from quadstep.tui.panels import MachinePanel
from test_tui import connected, make_app, positions
from tui_helpers import log_text, open_job, send_key, until


def state_line(app) -> str:  # noqa: ANN001
    return str(app.machine.query_one(MachinePanel).render()).splitlines()[0]


async def test_the_rapid_and_spindle_keys_change_a_running_job(machine: MachineConfig, emulator_binary: Path,
                                                               tmp_path: Path) -> None:
    job = tmp_path / "rapids.gcode"
    # feed moves at 5 mm/s to press the keys during, then rapids the override slows down
    job.write_text("G21 G90 F300\n" + "".join(f"G1 X{4 * k} Y{k % 2}\n" for k in range(1, 7)) + "G0 X40\nG0 X0 Y0\n")
    trace = tmp_path / "trace.csv"
    app = make_app(machine, emulator_binary, free=False, job_path=str(job), queue=127, trace=trace)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        speeds = app.session.machine.speed_overrides
        send_key(app, "greater_than_sign", ">")  # no job: for what runs next
        await until(pilot, lambda: "spindle override 110 %: for what runs next" in log_text(app),
                    what="the spindle override with no job")
        send_key(app, "less_than_sign", "<")
        await until(pilot, lambda: speeds.spindle == 100, what="the spindle override back at 100 %")
        assert " R" not in state_line(app)  # nothing shown at 100 %
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.line >= 2,
                    what="the job's second line")
        run = app.machine.job
        first_plan = run.plan
        send_key(app, "r", "r")
        send_key(app, "r", "r")  # 100 → 50 → 25 %
        for _ in range(5):
            send_key(app, "greater_than_sign", ">")
        await until(pilot, lambda: speeds.rapid == 25 and speeds.spindle == 150, what="the overrides")
        assert "rapid override 25 %: from the first move not yet sent" in log_text(app)
        await until(pilot, lambda: "R25 S150" in state_line(app), what="the overrides on the state line")
        await until(pilot, lambda: run.plan is not first_plan, what="the rest planned again")
        await until(pilot, lambda: "rapids.gcode: done" in log_text(app), what="the job to finish")
        assert positions(app) == machine.to_steps((0.0, 0.0, 0.0))
        # the rapids as the board ran them take up to four times as long as first planned (a quarter
        # of the speed; less where they accelerate, and where the board had the first rapid's start
        # before the keys): more than 2.5 times, which 50 % could not give. The trace, not the plan:
        # on a busy computer the board may run dry, and the job plans its rest again from there
        n_first = first_plan.base.segments.numpy()["n"].astype("int64")
        rapids_first = int(n_first[first_plan.base.move_ends[5]:].sum())
        steps = read_trace(trace)
        x = steps[steps[:, 1] == 0]
        from_x24 = x[int(np.argmax(np.cumsum(x[:, 2]) == machine.to_steps((24.0, 0.0, 0.0))[0])):, 0]
        assert int(from_x24[-1] - from_x24[0]) > 2.5 * rapids_first
        for _ in range(11):  # 150 → 200, then refused
            send_key(app, "greater_than_sign", ">")
        await until(pilot, lambda: "spindle override: 200 % is the most" in log_text(app),
                    what="the upper bound")
        send_key(app, "r", "r")
        await until(pilot, lambda: speeds.rapid == 100, what="the rapids back at 100 %")
