"""Probing (G38.2–G38.5): a straight move that ends where the probe touches (or lets go), with the
exact latched position (docs/INPUTS.md).

G38.2 moves toward the work until the probe touches, an error if it never does; G38.3 the same
without the error; G38.4 and G38.5 move away until contact is lost, with and without the error. At
the edge the firmware latches every axis's position and decelerates to rest (no crash into the
plate); the result gives the latched position in machine coordinates, and in work coordinates for
the work offset given.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Protocol

from ..config import MachineConfig
from ..kernel.fixed import MAX_AXES
from ..link import Link, hold, input_status, until_input
from ..planner.plan import plan_program
from ..planner.program import LinearMove, Program
from ..protocol import Input, InputChange, Probe
from ..protocol.wire import four_axes
from .errors import MachineError
from .standing import Standing


class ProbingMachine(Protocol):
    """What probing uses of a Machine (machine.py), which probes for jobs through this module."""

    config: MachineConfig
    link: Link
    decels: tuple[int, ...]
    standing: Standing  # the take-ups streamed, the positions latched and where it rests

    @property
    def position(self) -> tuple[int, ...]: ...

    def procedure(self, name: str) -> AbstractContextManager[object]: ...

    def sync(self) -> tuple[int, ...]: ...


# level, error if missed
CODES = {
    "38.2": (1, True),
    "38.3": (1, False),
    "38.4": (0, True),
    "38.5": (0, False),
}


class ProbeError(MachineError):
    """G38.2 / G38.4 ended without its edge, or the probe was there already."""


@dataclass(frozen=True)
class ProbeResult:
    code: str
    found: bool
    steps: tuple[int, ...]  # the latched step positions (the rest position when not found)
    machine_mm: tuple[float, ...]
    work_mm: tuple[float, ...]


def probe(
    machine: ProbingMachine,
    code: str,
    target_mm: Sequence[float],
    feed: float,
    work_offset: Sequence[float] | None = None,
    timeout: float = 600.0,
) -> ProbeResult:
    """Move toward `target_mm` (machine coordinates, inside the travel) at `feed` mm/s as G`code`
    does."""
    if code not in CODES:
        raise ProbeError(f"G{code}: not a probing code (G38.2, G38.3, G38.4, G38.5)")
    level, must = CODES[code]
    config, link = machine.config, machine.link
    offset = tuple(work_offset) if work_offset is not None else (0.0,) * len(config.axes)
    with machine.procedure(f"G{code}"):
        if input_status(link).is_active(Input.PROBE) == bool(level):
            raise ProbeError(f"G{code}: the probe is {'touching' if level else 'clear'} already")
        machine.sync()
        program = Program(items=[LinearMove(line=1, target=tuple(target_mm), feed=feed)], lines=1)
        # a target outside the travel: JobError
        plan = plan_program(program, config, machine.position)
        decel = four_axes(list(machine.decels) + [0] * (MAX_AXES - len(machine.decels)))
        segments = machine.standing.takeup_stream(plan.quadratic_segments())
        end = until_input(
            link,
            Probe(input=Input.PROBE, level=level, decel=decel),
            segments,
            timeout,
        )
        found = isinstance(end, InputChange)
        steps = machine.standing.shown(end.position, end.motion_ticks) if found else ()
        rest = machine.standing.rested(end.motion_ticks if found else None)
    if must and not found:
        raise ProbeError(
            f"G{code}: no contact {'made' if level else 'lost'} on the way to "
            + " ".join(f"{a.name}{x:g}" for a, x in zip(config.axes, target_mm))
        )
    steps = steps or rest
    machine_mm = config.to_mm(steps)
    return ProbeResult(
        code, found, steps, machine_mm, tuple(m - o for m, o in zip(machine_mm, offset))
    )


def hold_to_rest(machine: ProbingMachine) -> tuple[int, ...]:
    """The user's stop after a procedure was interrupted (Ctrl-C): HOLD, so that an axis decelerates
    to rest now instead of running out its queue; returns where it rests (take-ups excluded)."""
    done = hold(machine.link, machine.decels)
    return machine.standing.rested(done.hold_tick)
