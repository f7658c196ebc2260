"""Design tools built on the core: horizontal and vertical alignments, superelevation, circle chains, corner rounding, G2 fillets,
making paths of lines and tangent arcs G2 (``make_g2``).

Pure numpy/numba: nothing here imports a CAD kernel.
"""

from ..core.bezier import curvature_rate, peak_curvature_rate
from .alignment import Alignment, CurveData
from .centerline import Centerline3D, centerline_3d
from .circles import CircleChain, circle_chain
from .criteria import CriteriaRow, RailCriteria, RoadCriteria
from .fillets import FilletCorner, FilletedPath, fillet_path
from .g2 import G2Joint, G2Path, make_g2, smallest_max_deviation
from .profile import Profile, ProfileCriteria, VerticalCurve
from .rounded_paths import FilletedPolyline, RoundedCorner, RoundedPath, SpaceFillet, fillet_polyline, round_corners
from .rounding import CornerBatch, corner_legs, round_corners_batch
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
    "G2Joint",
    "G2Path",
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
    "make_g2",
    "peak_curvature_rate",
    "round_corners",
    "round_corners_batch",
    "smallest_max_deviation",
]
