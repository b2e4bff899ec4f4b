; DepoTwin test fixture: three print paths in the style of a slicer's output.
; Expected (mm, mm/s):
;   path 0: (10,10,0.2) -> (20,10,0.2) -> (20,20,0.2) at 10 mm/s
;   path 1: (20,20,0.2) -> (10,20,0.2)                at 20 mm/s (feed change)
;   path 2: (30,10,0.2) -> (40,10,0.2) -> (40,15,0.2) at 5 mm/s (relative section)
M117 Printing test square   ; text after an ignored command is not parsed
M104 S200
G21 ; millimetres
G90
M82
G28 ; home all axes
G92 E0

N10 G0 X10 Y10 Z0.2 F6000 *71 ; travel to the first corner (line number and checksum)
G1 X20 Y10 E1.0 F600    ; print 10 mm at 10 mm/s
g1 x20 y20 e2.0         ; lower case, same feed
G1 X10 Y20 E3.0 F1200   ; new feed rate: a new path from the same point
G1 E2.5 F2400           ; retract: no motion, nothing changes
G0 X30 Y10              ; travel ends the path
G1 E3.0                 ; prime
G92 E0                  ; reset the extruder
M83                     ; relative extrusion from here
G1 X40 Y10 E0.5 F300    ; 5 mm/s
G91                     ; relative positions
G1 Y5 E0.25 (inline comment)
G90
G1 X40 Y15 E0.1         ; no displacement: nothing printed
T0
G1 Z5 F3000             ; lift off
M84
