"""CAD adapters: OCCT edges and wires, the G2 continuity checkers of curves (``continuity``) and of faces
(``faces``), rolled-edge G2 solids (``slabs``; their swept surfaces ``roll_surfaces``; G2 prism edges
``prism_fillet``; all three through ``solids``), meshes for pictures, IGES and OCCT's STEP.

Every module here imports OCP (through build123d or CadQuery where named so), but ``sandbox``
(child processes for native code and slow writers), which builds use without the ``cad`` extra too.
"""
