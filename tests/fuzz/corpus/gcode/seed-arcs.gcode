; arcs: an R arc, an I/J full circle and a long R<0 arc (Marlin, relative E)
G21
G90
M83
G0 X10 Y0 Z0.2 F3000
G1 F1200
G3 X0 Y10 R10 E0.5 ; a quarter about the origin, counter-clockwise
G2 X0 Y10 I0 J-5 E1 ; a full circle of radius 5 about (0, 5), clockwise
G3 X10 Y0 R-10 E1.5 ; the long way round the origin: 270 degrees
