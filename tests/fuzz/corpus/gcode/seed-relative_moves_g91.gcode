; a G91 block: a 20 x 10 rectangle drawn with relative moves
G21
G90
M83
G1 X0 Y0 Z0.3 F1800
G91
G1 X20 E1
G1 Y10 E0.5
G1 X-20 E1
G1 Y-10 E0.5
G90
G0 X50 Y50
