"""quadstep host: plans motion into exact quadratic segments and streams them to the firmware."""

__version__ = "0.1.0"
