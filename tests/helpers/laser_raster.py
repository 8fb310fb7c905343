"""A LightBurn-style grayscale fill as a sender streams it, and the jobs a machine runs, recorded:
shared by the front door's raster test and the raster benchmark."""

from __future__ import annotations

import random

from quadstep.machine import JobRun, Machine


def raster_gcode(
    rows: int, pixels: int, feed_mm_min: float = 6000.0, seed: int = 5, relative: bool = False
) -> list[str]:
    """Rows of 0.1 mm pixels from X10 Y10, a `G1 X… S…` each under M4, every other row back;
    `relative`: the rows in G91, a step a line, as LightBurn writes them."""
    rng = random.Random(seed)
    lines = ["G21 G90 G94", "M4 S0", "G0 X10 Y10", f"G1 F{feed_mm_min:g}"]
    if relative:
        lines.append("G91")
    for row in range(rows):
        if relative:
            lines.append(f"G1 Y{0.1 if row else 0:.1f} S0")
        else:
            lines.append(f"G1 Y{10 + row * 0.1:.1f} S0")
        for k in range(1, pixels + 1):
            if relative:
                x = 0.1 if row % 2 == 0 else -0.1
            else:
                x = 10 + (k if row % 2 == 0 else pixels - k) * 0.1
            lines.append(f"G1 X{x:.1f} S{rng.randrange(1, 1000)}")
    return [*lines, "M5", *(["G90"] if relative else []), "G0 X0 Y0"]


def record_jobs(machine: Machine) -> list[JobRun]:
    """The jobs `machine` runs from now on, in the order they start."""
    jobs: list[JobRun] = []
    run_job = machine.run_job

    def recorded(*args: object, **kwargs: object) -> JobRun:
        job = run_job(*args, **kwargs)  # type: ignore[arg-type]
        jobs.append(job)
        return job

    machine.run_job = recorded  # type: ignore[method-assign]
    return jobs
