"""A job that sets every kind of modal state a start at a line must rebuild: inches, a work offset
set by G10 and made active (G55), relative moves (G91), a tool change, the spindle on, off and on
again at another speed, flood coolant, an arc. Its line 14 is the start the tests use."""

JOB = """\
G20 G90 G17
G10 L2 P2 X1 Y1 Z-0.2
G55
T2 M6
M3 S12000
G0 X0.5 Y0.5 Z0.1
G1 Z-0.04 F20
G91 G1 X0.5
G1 Y0.25
M5
G90 G0 Z0.1
M3 S9000 M8
G91 G1 Z-0.14 F10
G1 X-0.5 Y0.25
G90 G2 X1.5 Y1.0 I0.5 J0
G0 Z0.1
M30
"""
