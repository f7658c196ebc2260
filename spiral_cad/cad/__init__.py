"""CAD adapters: OCCT edges and wires, the G2 continuity checker, build123d and CadQuery.

Every module here imports OCP (through build123d or CadQuery where named so).
"""
