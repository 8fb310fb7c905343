(spindle spin-up dwell before cutting, as many posts write it)
G90 G21
M3 S24000
G4 P3
G0 X5 Y5
G0 Z1
G1 Z-0.5 F100
G1 X20 F500
G0 Z5
M5
G4 P1
M30
