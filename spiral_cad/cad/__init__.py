"""CAD adapters: OCCT edges and wires, the G2 continuity checker, build123d and CadQuery.

Every module here imports OCP (through build123d or CadQuery where named so), but ``sandbox``
(child processes for native code and slow writers), which builds use without the ``cad`` extra too.
"""
