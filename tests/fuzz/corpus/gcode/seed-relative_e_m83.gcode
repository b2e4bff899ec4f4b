; M83 relative extrusion, priming and retraction, numbers as Z.2 and E-.8
M83
G28
G1 Z.2 F3000
G1 X10 Y10 F6000 ; travel
G1 E.8 F2400 ; prime
G1 X30 Y10 E1.0 F1200
G1 X30 Y20 E0.5
G1 E-.8 F2400 ; retract
G0 X40 Y20 F6000
G1 E0.8 F2400
G1 X40 Y40 E1.0 F1200
G1 E-.8
