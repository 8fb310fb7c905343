%
(quadstep demo: a rounded frame, a circle and a star, engraved 0.3 mm deep)
(machine zero at the front-left corner, Z zero at the top)
N10 G21 G90 G17       ; millimetres, absolute coordinates, XY plane
N20 G0 Z0
N30 G0 X16 Y10        ; to the start of the frame

; the frame: 40 x 30 mm with 6 mm corner radius
N40 G1 Z-0.3 F300
N50 G1 X44 F2400
N60 G3 X50 Y16 I0 J6
N70 G1 Y34
N80 G3 X44 Y40 I-6 J0
N90 G1 X16
N100 G3 X10 Y34 R6
N110 G1 Y16
N120 G3 X16 Y10 R6
N130 G0 Z0

; a circle of 9 mm radius around the middle, as two half circles
N140 G0 X39 Y25
N150 G1 Z-0.3 F300
N160 G2 X21 Y25 I-9 J0 F1800
N170 G2 X39 Y25 I9 J0
N180 G0 Z0

; a five-pointed star inside the circle (relative moves)
N190 G0 X30 Y32
N200 G1 Z-0.3 F300
N210 G91 F1500
N220 G1 X4.11 Y-12.66
N230 G1 X-10.77 Y7.82
N240 G1 X13.32 Y0
N250 G1 X-10.77 Y-7.82
N260 G1 X4.11 Y12.66
N270 G90 G0 Z0

N280 G0 X0 Y0          ; home
N290 M30
%
