; firmware's own codes whose axis words are parameters (Bambu, Prusa, LinuxCNC probing)
M83
G91
G380 S2 Z30 F300
G380 S2 Z-25 F300
G90
G29.1 Z0
M1002 judge_flag g29_before_print_flag
M622 J1
G39 S1
M623
G28 W
G80 X32.5 Y40.2 W150 H120 ; mesh bed levelling
G38.2 Z-10 F50
G1 X10 Y10 Z0.2 F1200
G92 X0
G1 X5 E0.5
G92.2
G1 X5 E0.5
G92.3
G92.1
G1 X20 E0.5
G17
G2 Z1 I0.86 J0.86 P1 F20000
