"""The jog keys' choices: incremental or continuous, the step for X/Y (and other axes) and for Z
apart, the speed as a fraction of each axis's max_speed."""

from __future__ import annotations

from enum import Enum

from ..config import MachineConfig
from .settings import JogSettings


class JogMode(str, Enum):
    INCREMENTAL = "incremental"
    CONTINUOUS = "continuous"


class JogPresets:
    """Which preset each key chose; nothing here talks to a machine."""

    def __init__(self, config: MachineConfig, settings: JogSettings) -> None:
        self.config = config
        self.settings = settings
        self.mode = JogMode.INCREMENTAL
        steps = settings.step_presets
        self.step_index = steps.index(1.0) if 1.0 in steps else 0
        self.z_step_index = self.step_index
        self.speed_index = len(settings.speed_presets) // 2

    @property
    def distance(self) -> float:
        """The X/Y step (every axis but Z), mm."""
        return self.settings.step_presets[self.step_index]

    @property
    def z_distance(self) -> float:
        return self.settings.step_presets[self.z_step_index]

    def distance_for(self, axis: int) -> float:
        """The incremental step of `axis`, mm: Z has its own."""
        return self.z_distance if self.config.axes[axis].name == "Z" else self.distance

    @property
    def speed_fraction(self) -> float:
        return self.settings.speed_presets[self.speed_index]

    def speed(self, axis: int) -> float:
        """The selected jog speed of `axis`, mm/s."""
        return self.speed_fraction * self.config.axes[axis].max_speed

    def select_step(self, index: int) -> None:
        """The X/Y step."""
        self.step_index = self._step_preset(index)

    def select_z_step(self, index: int) -> None:
        self.z_step_index = self._step_preset(index)

    def change_z_step(self, delta: int) -> None:
        self.z_step_index = min(
            max(self.z_step_index + delta, 0), len(self.settings.step_presets) - 1
        )

    def change_speed(self, delta: int) -> None:
        self.speed_index = min(
            max(self.speed_index + delta, 0), len(self.settings.speed_presets) - 1
        )

    def toggle_mode(self) -> JogMode:
        self.mode = JogMode.CONTINUOUS if self.mode == JogMode.INCREMENTAL else JogMode.INCREMENTAL
        return self.mode

    def copy_presets(self, other: JogPresets) -> None:
        """Take over another's choices (a new connection keeps them)."""
        self.mode, self.speed_index = other.mode, other.speed_index
        self.step_index, self.z_step_index = other.step_index, other.z_step_index

    def _step_preset(self, index: int) -> int:
        if not 0 <= index < len(self.settings.step_presets):
            raise ValueError(
                f"step preset {index + 1} does not exist (1 … {len(self.settings.step_presets)})"
            )
        return index
