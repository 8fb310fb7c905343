"""How long a job may take, checked before it is planned: otherwise a plan of any length would be
made (a feed of 1e-10 mm/min, an hour's dwell ten thousand times), taking as long as it lasts.

A job may move (and dwell) for at most 2^32 ticks, what the board's 32-bit motion tick counter
counts once: every tick the board reports during a job (a hold's, an input's, an alarm's, the
run's total) is read against the tick the job started at, which is unambiguous only while the job
is shorter than the counter's range. That is 37.3 h at 32 kHz and 23.9 h at 50 kHz. (One dwell
lasts at most MAX_DWELL_S, program.py.)
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..config import MachineConfig
from .moves import MoveTable
from .program import Dwell, JobError

MAX_JOB_TICKS = 1 << 32


def _limit(config: MachineConfig) -> str:
    seconds = MAX_JOB_TICKS / config.tick_hz
    return (
        f"a job may move for at most {seconds / 3600:.1f} h ({seconds:.0f} s: 2^32 ticks, the "
        f"range of the board's motion tick counter, at tick_hz {config.tick_hz})"
    )


def move_ticks(length: float, u_in: float, u_out: float, u_max: float, accel: float) -> float:
    """The fewest ticks a move of `length` mm can take from speed u_in to u_out (mm/tick), at most
    u_max and accelerating at most `accel` (mm/tick²): infinite when it cannot move at all."""
    if u_max <= 0.0 or accel <= 0.0:
        return math.inf
    peak = min(u_max, math.sqrt((2.0 * accel * length + u_in * u_in + u_out * u_out) / 2.0))
    peak = max(peak, u_in, u_out)
    ramps = (2.0 * peak - u_in - u_out) / accel
    cruise = length - (2.0 * peak * peak - u_in * u_in - u_out * u_out) / (2.0 * accel)
    return ramps + max(0.0, cruise) / peak


def check_duration(
    table: MoveTable,
    config: MachineConfig,
    label: str,
    entry: Sequence[float] | None = None,
    before: float = 0.0,
) -> float:
    """Raise JobError when the job's motion and dwells last more than MAX_JOB_TICKS, naming the
    line where they pass it (and the feed or accel that makes one move alone too long). Without
    `entry` (the junction speeds) each move counts at its top speed only: a bound to check before
    the look-ahead runs. `before`: the ticks of the job before the table (a file checked a part at a
    time); returns the ticks up to the table's end."""
    limit = float(MAX_JOB_TICKS)
    hz = float(config.tick_hz)
    total = before
    stops = iter(table.stops)
    stop = next(stops, None)
    for k in range(len(table) + 1):
        while stop is not None and stop[0] <= k:
            if isinstance(stop[1], Dwell):
                total += stop[1].seconds * hz
                if total > limit:
                    raise JobError(
                        f"{label} {stop[1].line}: the job's motion and dwells up to "
                        f"here last {total / hz / 3600:.1f} h; {_limit(config)}"
                    )
            stop = next(stops, None)
        if k == len(table):
            break
        if entry is None:
            top = table.max_speed[k]
            ticks = table.length[k] / top if top > 0 else math.inf
        else:
            ticks = move_ticks(
                table.length[k], entry[k], entry[k + 1], table.max_speed[k], table.accel[k]
            )
        if ticks > limit:
            raise JobError(_too_long(table, k, ticks, config, label))
        total += ticks
        if total > limit:
            raise JobError(
                f"{label} {table.line[k]}: the job's motion and dwells up to here last "
                f"at least {total / hz / 3600:.1f} h; {_limit(config)}"
            )
    return total


def _too_long(table: MoveTable, k: int, ticks: float, config: MachineConfig, label: str) -> str:
    """One move longer than a whole job may be: what makes it so (and the least feed that would
    do)."""
    hz = float(config.tick_hz)
    length = table.length[k]
    where = f"{label} {table.line[k]}"
    lasting = f"this {length:.4g} mm move last at least {ticks / hz:.3g} s"
    top = table.max_speed[k]
    if top <= 0 or length / top > MAX_JOB_TICKS:
        which = "its feed" if table.feed[k] <= top else "max_speed of its axes"
        least = length / (MAX_JOB_TICKS / hz)
        return (
            f"{where}: {which}, {_speed(top * hz)}, would make {lasting}: the slowest feed for "
            f"it is {_speed(least)}; {_limit(config)}"
        )
    which = "its accel" if table.accel_cap[k] <= table.accel[k] else "max_accel of its axes"
    accel = table.accel[k] * hz * hz
    return (
        f"{where}: {which}, {accel:.3g} mm/s² along the path, would make {lasting}; "
        f"{_limit(config)}"
    )


def _speed(mm_per_s: float) -> str:
    return f"{mm_per_s:.3g} mm/s ({mm_per_s * 60:.3g} mm/min)"
