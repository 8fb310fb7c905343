; bCNC-style file: lower case, comments of both kinds, line numbers, program markers
%
n1 g21 g90 (metric, absolute)
n2 g0 z5 ; safe height
n3 m3 s9000
n4 g0 x10 y10
n5 g1 z-1 f250
n6 g1 x30 y10 f750
n7 g2 x30 y30 r10
n8 g1 x10 y30
n9 g3 x10 y10 r10
n10 g0 z5
n11 m5
n12 m30
%
