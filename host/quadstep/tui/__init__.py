"""`quadstep tui`: a terminal sender with positions, jogging, jobs and link health."""

from .app import QuadstepApp
from ..machine import Target
from .session import Session

__all__ = ["QuadstepApp", "Session", "Target"]
