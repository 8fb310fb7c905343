"""Jogging on a Machine, independent of any user interface: presets, soft limits, continuous jogs
stopped by HOLD."""

from .jogger import Jogger, JogResult
from .presets import JogMode, JogPresets
from .release import ReleaseDetector
from .settings import JogSettings
from .step_queue import QueuedStep, StepQueue

__all__ = [
    "JogMode",
    "JogPresets",
    "JogResult",
    "JogSettings",
    "Jogger",
    "QueuedStep",
    "ReleaseDetector",
    "StepQueue",
]
