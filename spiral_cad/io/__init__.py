"""File formats that need no CAD kernel: STEP text, SVG, DXF out and in (through ezdxf), samples CSV,
G-code in (as a polyline, or as lines and arcs) and out, point files in, OpenDRIVE model, writer, reader and checker, LandXML out and in,
DXF drawings, LandXML and OpenDRIVE files rewritten G2 in place
(``dxf_g2.rewrite_dxf_g2``, ``landxml_g2.rewrite_landxml_g2``, ``opendrive_g2.rewrite_opendrive_g2``, with a
``document_report.DocumentReport``),
and all-or-nothing output staging.

IGES and the STEP of solids go through OCCT and live in ``spiral_cad.cad``. This namespace names the
readers, writers and rewriters (``from spiral_cad.io import read_dxf_paths``); each loads with its module
on first use.
"""

from ..core.namespaces import lazy_names

#: The names of this namespace and the module each lives in (loaded on first use: the package itself imports nothing).
_HOMES = {
    "read_dxf_paths": "dxf_read",
    "write_dxf": "dxf",
    "rewrite_dxf_g2": "dxf_g2",
    "parse_gcode": "gcode",
    "read_gcode": "gcode",
    "parse_gcode_chain": "gcode",
    "read_gcode_chain": "gcode",
    "parse_gcode_moves": "gcode_paths",
    "read_gcode_moves": "gcode_paths",
    "read_gcode_runs": "gcode_paths",
    "GcodeRuns": "gcode_paths",
    "write_gcode": "gcode_write",
    "gcode_program": "gcode_write",
    "rewrite_gcode_g2": "gcode_inplace",
    "run_rs274": "rs274",
    "read_landxml": "landxml_read",
    "write_landxml": "landxml",
    "rewrite_landxml_g2": "landxml_g2",
    "read_opendrive": "opendrive",
    "read_network": "opendrive",
    "write_opendrive": "opendrive",
    "check_opendrive": "opendrive",
    "rewrite_opendrive_g2": "opendrive_g2",
    "read_ifc_alignments": "ifc",
    "check_ifc": "ifc_check",
    "check_landxml": "landxml_check",
    "write_ifc": "ifc",
    "read_points": "points",
    "parse_points": "points",
    "write_samples": "samples",
    "write_step": "step",
    "write_svg": "svg",
    "round_toolpath": "toolpath_rounding",
    "DocumentReport": "document_report",
    "PathReport": "document_report",
}
__all__ = sorted(_HOMES)

__getattr__, __dir__ = lazy_names(__name__, _HOMES)
