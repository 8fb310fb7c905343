"""`quadstep tui`: a terminal sender with positions, jogging, jobs and link health."""

from .app import QuadstepApp
from .session import Session, Target

__all__ = ["QuadstepApp", "Session", "Target"]
