"""File formats: STEP, IGES, DXF, SVG and OpenDRIVE writers (and the OpenDRIVE reader).

STEP, SVG and OpenDRIVE are written directly and need no CAD kernel; IGES
goes through OCCT's writer (OCP) and DXF through ezdxf. The public entry
points are in ``spiral_cad.export``.
"""
