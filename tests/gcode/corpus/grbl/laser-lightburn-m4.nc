; LightBurn 1.4.03
; GRBL device profile, absolute coords
; Bounds: X5 Y5 to X45 Y35
G00 G17 G40 G21 G54
G90
M4
; Cut @ 1000 mm/min, 80% power
M8
G0 X5Y5
; Layer C00
G1 X45S800F1000
G1 Y35
G1 X5
G1 Y5
; Cut @ 1500 mm/min, 40% power
G0 X10Y10
G1 X40S400F1500
G1 Y30
G1 X10
G1 Y10
M9
G1 S0
M5
G90
; return to user-defined finish pos
G0 X0 Y0
M2
