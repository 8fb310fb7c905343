(a file in inches, feeds in inches per minute)
G20 G90 G17
G0 Z0.2
G0 X0.5 Y0.5
M3 S15000
G1 Z-0.04 F10
G1 X1.5 F40
G2 X1.75 Y0.75 I0 J0.25
G1 Y1.25
G1 X0.5
G1 Y0.5
G0 Z0.2
M5
G21
M30
