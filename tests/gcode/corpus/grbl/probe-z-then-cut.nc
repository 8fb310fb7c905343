(touch off Z with a probe plate 10 mm thick, then cut: a sender-style job)
G21 G90
G38.2 Z-40 F100
G10 L20 P1 Z10
G0 Z15
G0 X10 Y10
M3 S12000
G1 Z-1 F200
G1 X30 F600
G0 Z15
M5
M30
