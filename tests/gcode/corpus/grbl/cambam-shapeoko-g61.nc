( Made using CamBam - http://www.cambam.co.uk )
( ShapeOko profile, exact stop )
( T1 : 3.175 )
G21 G90 G91.1 G61 G40
G0 Z5.0
T1 M6
G17
M3 S10000
G0 X0.0 Y0.0
G1 F250.0 Z-0.8
G1 F700.0 X20.0
G1 Y20.0
G1 X0.0
G1 Y0.0
G64 P0.01
G1 F250.0 Z-1.6
G1 F700.0 X20.0
G1 Y20.0
G1 X0.0
G1 Y0.0
G0 Z5.0
M5
M30
