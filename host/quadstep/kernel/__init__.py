"""The fixed-point kernel: the numbers the firmware computes with, the motion it is given in them
(quadratic and cubic segments), the firmware's chain of cubic state, and the exact prediction of
every step (docs/FIXED_POINT.md, docs/CUBIC.md). Every layer may import it; it imports nothing else
of quadstep."""
