"""The feed override keys while a job runs (- + *): 10 % steps within 10–200 %, shown on the job line, applied
to what is not yet sent; the job still ends exactly on its last target. (Keys go in as the terminal delivers
them: the pilot's press waits for the job's progress bar to stop moving.)"""

from __future__ import annotations

from pathlib import Path

from quadstep.config import MachineConfig
from quadstep.machine.override import first_difference
from quadstep.tui.panels import JobPanel
from test_tui import connected, make_app, positions
from tui_helpers import log_text, send_key, until, open_job


def job_line(app) -> str:  # noqa: ANN001
    return str(app.machine.query_one(JobPanel).query_one("#job-label").render())


async def test_the_feed_override_keys_change_a_running_job(machine: MachineConfig, emulator_binary: Path,
                                                           tmp_path: Path) -> None:
    job = tmp_path / "steps.gcode"
    job.write_text("G21 G90 F300\n" + "".join(f"G1 X{4 * k} Y{k % 2}\n" for k in range(1, 11)))  # 5 mm/s
    # real time, with the job's whole lookahead (1.5 s) queued: a test machine deep into a full run has paused
    # this process for a third of a second (a garbage collection), more than 32 slots of 20 ms hold
    app = make_app(machine, emulator_binary, free=False, job_path=str(job), queue=127)
    async with app.run_test(size=(80, 24)) as pilot:
        await connected(pilot, app)
        await pilot.press("minus")  # no job: the jog speed, not a feed override
        assert "feed override" not in log_text(app)
        await open_job(pilot)
        await until(pilot, lambda: app.machine.job is not None and app.machine.job.progress.line >= 2,
                    what="the job's second line")
        run = app.machine.job
        first_plan = run.plan
        send_key(app, "minus", "-")
        await until(pilot, lambda: run.feed_override == 90 and "feed override 90 %" in log_text(app),
                    what="the override at 90 %")
        await until(pilot, lambda: "feed 90 %" in job_line(app), what="the override on the job line")
        await until(pilot, lambda: run.plan is not first_plan, what="the rest planned again at 90 %")
        at_90 = first_difference(first_plan.segments, run.plan.segments)  # where the 90 % plan begins
        await until(pilot, lambda: run.progress.done > at_90, what="the board running the rest at 90 %")
        for _ in range(12):  # 90 → 200, then once more: refused
            send_key(app, "plus", "+")
        await until(pilot, lambda: "feed override: 200 % is the most" in log_text(app), what="the upper bound")
        assert run.feed_override == 200 and "feed 200 %" in job_line(app)
        send_key(app, "asterisk", "*")
        await until(pilot, lambda: run.feed_override == 100 and log_text(app).endswith("feed override 100 %: from "
                                                                                    "the first move not yet sent"),
                    what="the override back at 100 %")
        await until(pilot, lambda: "steps.gcode: done" in log_text(app), what="the job to finish")
        assert positions(app) == machine.to_steps((40.0, 0.0, 0.0))
        # what was sent: the first part, then the rest at 90 % (and the overrides after it)
        assert first_difference(first_plan.segments, run.plan.segments) == at_90 < len(first_plan)
