"""Design tools built on the core: horizontal and vertical alignments, superelevation, circle chains, corner rounding, G2 fillets.

Pure numpy/numba: nothing here imports a CAD kernel.
"""

from ..core.bezier import curvature_rate, peak_curvature_rate
from .alignment import Alignment, CurveData
from .centerline import Centerline3D, centerline_3d
from .circles import CircleChain, circle_chain
from .criteria import CriteriaRow, RailCriteria, RoadCriteria
from .fillets import FilletCorner, FilletedPath, fillet_path
from .profile import Profile, ProfileCriteria, VerticalCurve
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
from .superelevation import Superelevation
from .survey import SurveyFit, fit_survey

__all__ = [
    "Alignment",
    "Centerline3D",
    "CircleChain",
    "CornerBatch",
    "CriteriaRow",
    "CurveData",
    "FilletCorner",
    "FilletedPath",
    "FilletedPolyline",
    "Profile",
    "ProfileCriteria",
    "RailCriteria",
    "RoadCriteria",
    "RoundedCorner",
    "RoundedPath",
    "SpaceFillet",
    "Superelevation",
    "SurveyFit",
    "VerticalCurve",
    "centerline_3d",
    "circle_chain",
    "corner_legs",
    "curvature_rate",
    "fillet_path",
    "fillet_polyline",
    "fit_survey",
    "peak_curvature_rate",
    "round_corners",
    "round_corners_batch",
]
