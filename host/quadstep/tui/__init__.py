"""`quadstep tui`: a terminal sender with positions, jogging, jobs and link health."""

from ..machine import Target
from .app import QuadstepApp
from .session import Session

__all__ = ["QuadstepApp", "Session", "Target"]
