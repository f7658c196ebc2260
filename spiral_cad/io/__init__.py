"""File formats that need no CAD kernel: STEP text, SVG, DXF out and in (through ezdxf), samples CSV,
G-code in (as a polyline, or as lines and arcs) and out, point files in, OpenDRIVE model, writer, reader and checker, LandXML out and in
(``read_landxml``, loaded on first use), DXF drawings, LandXML and OpenDRIVE files rewritten G2 in place
(``dxf_g2.rewrite_dxf_g2``, ``landxml_g2.rewrite_landxml_g2``, ``opendrive_g2.rewrite_opendrive_g2``, with a
``document_report.DocumentReport``),
and all-or-nothing output staging.

IGES and the STEP of solids go through OCCT and live in ``spiral_cad.cad``.
"""

from typing import Any


def __getattr__(name: str) -> Any:
    """``read_landxml`` on first use (the package itself imports nothing)."""
    if name == "read_landxml":
        from .landxml_read import read_landxml

        return read_landxml
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
