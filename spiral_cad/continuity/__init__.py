"""Continuity checks: joint measures (gap, tangent angle, curvature jump) and their verdicts.

Pure numpy: nothing here reads files or imports a CAD kernel. The file readers
(``spiral_cad.io``) and the OCCT checker (``spiral_cad.cad.continuity``) feed it.
"""

from .joints import Continuity, ContinuityReport, Frame, JointReport, Timing, WireReport, classify_pieces

__all__ = ["Continuity", "ContinuityReport", "Frame", "JointReport", "Timing", "WireReport", "classify_pieces"]
