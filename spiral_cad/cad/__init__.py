"""CAD adapters: OCCT edges and wires, the G2 continuity checkers of curves (``continuity``) and of faces
(``faces``), rolled-edge G2 solids (``slabs``; their swept surfaces ``roll_surfaces``; G2 prism edges
``prism_fillet``; all three through ``solids``), meshes for pictures, IGES and OCCT's STEP.

Every module here imports OCP (through build123d or CadQuery where named so), but ``sandbox``
(child processes for native code and slow writers), which builds use without the ``cad`` extra too.
This namespace names the exporters, readers, checkers and G2 makers (``from spiral_cad.cad import
check_faces``); each loads with its module on first use, so importing the namespace imports no OCP.
"""

from ..core.namespaces import lazy_names

#: The names of this namespace and the module each lives in (loaded on first use: each needs OCP).
_HOMES = {
    "export_step": "export",
    "export_iges": "export",
    "export_dxf": "export",
    "export_svg": "export",
    "export_samples": "export",
    "export_opendrive": "export",
    "read_shape": "readers",
    "ReadError": "readers",
    "check_continuity": "continuity",
    "curvature_comb": "continuity",
    "ContinuityReport": "continuity",
    "check_faces": "faces",
    "FaceReport": "faces",
    "rolled_slab": "slabs",
    "continuous_box": "slabs",
    "fillet_part_edges": "stack_fillet",
    "fillet_prism_edges": "prism_fillet",
    "fillet_wire": "fillet",
    "fillet_face": "fillet",
    "g2_wire": "g2wire",
    "g2_face": "g2wire",
    "rewrite_step_g2": "step_g2",
    "rewrite_iges_g2": "step_g2",
}
__all__ = sorted(_HOMES)

#: Old names, for one release: ``g2_slab`` is build123d's (a ``Part``); this layer's (a ``Slab``) is ``rolled_slab``.
__getattr__, __dir__ = lazy_names(__name__, _HOMES, renamed={"g2_slab": "rolled_slab"})
