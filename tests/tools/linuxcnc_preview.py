"""Run by LinuxCNC's own Python (/usr/bin/python3 with Debian's linuxcnc-uspace): the moves of a G-code program
(argv[1]) as LinuxCNC's interpreter library executes them -- the `gcode` module behind its AXIS preview, which
evaluates G5 splines (60 points on the cubic) and arcs (its own arc_to_segments) in double precision -- in the
program's unit (argv[2]: mm or in), printed as one JSON object: {"result": [...], "moves": [[kind, line, x, y, z]]}."""

import json
import os
import sys
import tempfile

import gcode
from rs274.interpret import Translated

SCALE = 25.4 if sys.argv[2] == "mm" else 1.0  # the library reports inches (get_external_length_units)


class Canon(Translated):
    rotation_cos, rotation_sin = 1.0, 0.0

    def __init__(self, folder):
        self.parameter_file = os.path.join(folder, "params.var")
        self.moves, self.line, self.plane = [], 0, 1
        self.lo = (0.0,) * 9

    def add(self, kind, point):
        self.moves.append([kind, self.line] + [v * SCALE for v in point[:3]])
        self.lo = tuple(point)

    def next_line(self, state):
        self.line = state.sequence_number

    def straight_feed_translated(self, *point):
        self.add("feed", point)

    def straight_traverse_translated(self, *point):
        self.add("rapid", point)

    def arc_feed(self, *arc):
        for point in gcode.arc_to_segments(self, *arc, 64):
            self.add("arc", point)

    def set_plane(self, plane):
        self.plane = plane

    def get_external_angular_units(self):
        return 1.0

    def get_external_length_units(self):
        return 1.0 / 25.4

    def get_axis_mask(self):
        return 7

    def get_block_delete(self):
        return 0

    def get_tool(self, number):
        return (number,) + (0.0,) * 12 + (0,)

    def check_abort(self):
        return False

    def ignored(self, *arguments):
        pass

    comment = message = set_feed_rate = set_feed_mode = set_traverse_rate = tool_offset = ignored
    change_tool = dwell = user_defined_function = ignored


with tempfile.TemporaryDirectory() as folder:
    canon = Canon(folder)
    result = gcode.parse(sys.argv[1], canon, "", "")
print(json.dumps({"result": list(result), "moves": canon.moves}))
