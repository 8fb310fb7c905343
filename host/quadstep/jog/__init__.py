"""Jogging on a Machine, independent of any user interface: presets, soft limits, continuous jogs
stopped by HOLD."""

from .jogger import JogMode, JogResult, Jogger
from .release import ReleaseDetector
from .settings import JogSettings

__all__ = ["JogMode", "JogResult", "JogSettings", "Jogger", "ReleaseDetector"]
