"""File formats that need no CAD kernel: STEP text, SVG, DXF (through ezdxf), samples CSV,
G-code in, point files in, OpenDRIVE model, writer, reader and checker, and all-or-nothing output staging.

IGES and the STEP of solids go through OCCT and live in ``spiral_cad.cad``.
"""
