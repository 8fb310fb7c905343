(zero here with G92, as a sender's "zero" button does, then clear it)
G21 G90
G0 X20 Y20
G92 X0 Y0
G0 Z1
M3 S8000
G1 Z-0.2 F200
G1 X10 F600
G1 Y10
G1 X0
G1 Y0
G0 Z5
M5
G92.1
G0 X0 Y0
M30
