"""G2 solids: a closed planar G2 outline extruded with rolled (curvature-continuous) top and bottom edges.

One import for the three parts of the G2 solids, each documented in its own module:
``roll_surfaces`` (the roll profile swept along the outline as NURBS surfaces, and
what a STEP note says of them), ``slabs`` (``rolled_slab``, ``continuous_box``, the
checks of the solid) and ``prism_fillet`` (G2 fillets of a right prism's straight edges).
"""

from __future__ import annotations

from .prism_fillet import PLAN_OVER_REACH, fillet_prism_edges, plan_radius
from .roll_surfaces import PROFILES, recorded_approximation, roll_profile
from .slabs import (
    Slab,
    approximation_note,
    continuous_box,
    expected_level,
    forward_solid,
    outline_segments,
    rolled_slab,
    verify_faces,
    verify_solid,
)

__all__ = [
    "PROFILES",
    "Slab",
    "approximation_note",
    "continuous_box",
    "fillet_prism_edges",
    "forward_solid",
    "rolled_slab",
    "outline_segments",
    "expected_level",
    "plan_radius",
    "PLAN_OVER_REACH",
    "recorded_approximation",
    "roll_profile",
    "verify_faces",
    "verify_solid",
]
