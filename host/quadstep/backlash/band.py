"""Where each carriage sits in its dead band, and the positions that exclude the take-up.

A motor pushes its carriage through a dead band of `size` steps: `w` (0 … size) is how far the motor
is from the band's negative side, so `w = size` after a push in +, `w = 0` after a push in −. A
motor step moves the carriage only at a side (w stays), otherwise it moves the motor within the band
(w changes): the carriage is `motor − w` plus a constant. The position every report shows — status,
the TUI, `run`, probing, homing — is that carriage position, `motor − base − w`: a take-up moves the
motor and `w` together and leaves it unchanged. `w` is unknown (None) until an axis first moves; its
first motion then takes no take-up and puts it on that side (base chosen so that the position stays
where it was).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace

from pydantic import BaseModel, ConfigDict

from ..config import MachineConfig


@dataclass(frozen=True)
class BandAxis:
    """One axis: band size (steps), where the motor is in it (None: not known yet), and the
    constant."""

    size: int = 0
    w: int | None = None
    base: int = 0

    def offset(self) -> int:
        """motor − position."""
        return self.base + (self.w if self.w is not None else 0)

    def take(self, direction: int) -> int:
        """The take-up a motion in `direction` needs first (signed steps; 0 when w is not known)."""
        if self.w is None or self.size == 0:
            return 0
        return (self.size - self.w) if direction > 0 else -self.w

    def adopt(self, direction: int) -> BandAxis:
        """Known from here on: a first motion in `direction`, with no take-up, puts the motor on
        that side."""
        if self.w is not None:
            return self
        w = self.size if direction > 0 else 0
        return replace(self, w=w, base=self.base - w)

    def moved(self, steps: Iterable[int]) -> BandAxis:
        """After the motor made these signed steps (in order): each moves w within the band, or the
        carriage."""
        axis = self
        for s in steps:
            if axis.w is None:
                axis = axis.adopt(s)
            assert axis.w is not None  # known once adopted
            axis = replace(axis, w=min(axis.size, max(0, axis.w + s)))
        return axis

    def monotone(self, delta: int) -> BandAxis:
        """After a motion of `delta` steps all in one direction (a hold's deceleration, a straight
        run)."""
        if delta == 0:
            return self
        axis = self.adopt(delta) if self.w is None else self
        assert axis.w is not None  # known once adopted
        return replace(axis, w=min(axis.size, max(0, axis.w + delta)))


@dataclass(frozen=True)
class Band:
    """Every axis of a machine."""

    axes: tuple[BandAxis, ...] = field(default_factory=tuple)

    @classmethod
    def of(cls, config: MachineConfig) -> Band:
        return cls(tuple(BandAxis(size=a.backlash_steps) for a in config.axes))

    def to_position(self, motor: Sequence[int]) -> tuple[int, ...]:
        """The positions reports show (take-ups excluded) for these motor step counts."""
        return tuple(m - a.offset() for m, a in zip(motor, self.axes)) + tuple(
            motor[len(self.axes) :]
        )

    def to_motor(self, position: Sequence[int]) -> tuple[int, ...]:
        return tuple(p + a.offset() for p, a in zip(position, self.axes)) + tuple(
            position[len(self.axes) :]
        )

    def with_axis(self, i: int, axis: BandAxis) -> Band:
        return Band(self.axes[:i] + (axis,) + self.axes[i + 1 :])

    @property
    def active(self) -> bool:
        return any(a.size for a in self.axes)


class BandRecord(BaseModel):
    """The band kept between runs (in the state file): valid only while the board still counts
    `motor`."""

    model_config = ConfigDict(extra="forbid")

    size: list[int]
    w: list[int | None]
    base: list[int]
    motor: list[int]

    @classmethod
    def of(cls, band: Band, motor: Sequence[int]) -> BandRecord:
        return cls(
            size=[a.size for a in band.axes],
            w=[a.w for a in band.axes],
            base=[a.base for a in band.axes],
            motor=list(motor[: len(band.axes)]),
        )

    def restore(self, config: MachineConfig, motor: Sequence[int]) -> Band:
        """The kept band if it still describes this machine (same sizes, the board where it was);
        else a new one."""
        fresh = Band.of(config)
        if self.size != [a.size for a in fresh.axes] or self.motor != list(
            motor[: len(fresh.axes)]
        ):
            return fresh
        return Band(tuple(BandAxis(s, w, b) for s, w, b in zip(self.size, self.w, self.base)))


__all__ = ["Band", "BandAxis", "BandRecord"]
