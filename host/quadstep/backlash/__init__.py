"""Backlash: the carriage's dead band, its take-up inside the motion, and its measurement
(docs/BACKLASH.md)."""
