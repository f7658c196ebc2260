"""Design tools built on the core: horizontal alignments, circle chains, corner rounding, G2 fillets.

Pure numpy/numba: nothing here imports a CAD kernel.
"""

from .alignment import Alignment, CurveData, curvature_rate, peak_curvature_rate
from .circles import CircleChain, circle_chain
from .criteria import CriteriaRow, RailCriteria, RoadCriteria
from .fillets import FilletCorner, FilletedPath, fillet_path
from .rounding import (
    CornerBatch,
    FilletedPolyline,
    RoundedCorner,
    RoundedPath,
    SpaceFillet,
    corner_legs,
    fillet_polyline,
    round_corners,
    round_corners_batch,
)

__all__ = [
    "Alignment",
    "CircleChain",
    "CornerBatch",
    "CriteriaRow",
    "CurveData",
    "FilletCorner",
    "FilletedPath",
    "FilletedPolyline",
    "RailCriteria",
    "RoadCriteria",
    "RoundedCorner",
    "RoundedPath",
    "SpaceFillet",
    "circle_chain",
    "corner_legs",
    "curvature_rate",
    "fillet_path",
    "fillet_polyline",
    "peak_curvature_rate",
    "round_corners",
    "round_corners_batch",
]
