; a helical ramp as straight moves, incremental, in inches
G20 G91
G1 X1 F20
G1 X0.5 Y0.866 Z-0.05
G1 X-0.5 Y0.866 Z-0.05
g1 x-1 z-0.05
G1 X-0.5 Y-0.866 Z-0.05
G1 X0.5 Y-0.866 Z-0.05
G1 X1 Z-0.05
