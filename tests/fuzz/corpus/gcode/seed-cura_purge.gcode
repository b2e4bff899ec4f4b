;FLAVOR:Marlin
;Generated the way Cura 4.13 starts a print: absolute E and a purge line
M140 S60
M104 S200
M190 S60
M109 S200
M82 ;absolute extrusion mode
G28 ;Home
G92 E0 ;Reset Extruder
G1 Z2.0 F3000 ;Move Z Axis up
G1 X0.1 Y20 Z0.3 F5000.0 ;Move to start position
G1 X0.1 Y200.0 Z0.3 F1500.0 E15 ;Draw the first line
G1 X0.4 Y200.0 Z0.3 F5000.0 ;Move to side a little
G1 X0.4 Y20 Z0.3 F1500.0 E30 ;Draw the second line
G92 E0 ;Reset Extruder
G1 Z2.0 F3000 ;Move Z Axis up
G92 E0
G92 E0
G1 F2700 E-5
;LAYER_COUNT:1
;LAYER:0
M107
G0 F6000 X10 Y10 Z0.3
;TYPE:WALL-OUTER
G1 F2700 E0
G1 F1200 X20 Y10 E0.33
G1 X20 Y20 E0.66
M107
M104 S0
M140 S0
;End of Gcode
