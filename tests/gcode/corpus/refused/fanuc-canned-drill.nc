(Mach3/Fanuc-style drilling with a canned cycle)
G21 G90 G17
G0 Z5
M3 S3000
G81 X10 Y10 Z-5 R2 F100
X20
X30
G80
M5
M30
