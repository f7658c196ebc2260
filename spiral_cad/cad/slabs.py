"""G2 slabs: a closed planar outline extruded with G2-rolled top and bottom edges, checked before it is returned.

The input is checked first (the outline is closed, G2 and does not cross
itself; the rolls fit inside it), then each outline piece gives a wall face
and two roll faces (``roll_surfaces``); they are sewn with the two planar caps
into one solid, which is checked valid and closed, and its faces' continuity
verified, before anything is returned. ``continuous_box`` is the rectangle's case.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_SHELL, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape, TopoDS_Solid

from ..core.chain import JOIN_TOLERANCE, Chain, g2_mismatch
from ..core.errors import NoSolutionError
from ..core.inputs import as_float, shown
from ..core.segments import Segment
from ..core.shapes import DEFAULT_SHAPE
from ..core.units import DEFAULT_UNITS, length_unit
from ..design.fillets import TANGENT_TOL, continuous_rectangle
from .advice import advice, refusal
from .roll_surfaces import roll_profile
from .stacks import _FIT_SLACK, Wall, _between, _fit_problem, _inside, _plain, _samples, _signed_area, meeting_problem, stack_solid

__all__ = [
    "Slab",
    "approximation_note",
    "continuous_box",
    "expected_level",
    "forward_solid",
    "rolled_slab",
    "outline_segments",
    "verify_faces",
    "verify_solid",
]

#: A joint of the outline turning more than this (radians) is a corner no roll can follow.
_CORNER_TOL = 1e-7


@dataclass(frozen=True)
class Slab:
    """A G2 slab and what its construction guarantees.

    Attributes:
        shape: the solid (OCP ``TopoDS_Solid``), checked valid and closed.
        approximation: the largest deviation of a non-exact patch (over a
            spiral of the outline) from the true sweep, in the outline's unit;
            0.0 when every patch is exact.
        roll: the horizontal (= vertical) extent of the top and bottom rolls.
        height: the slab's height.
        units: the length unit of the numbers.
    """

    shape: TopoDS_Solid
    approximation: float
    roll: tuple[float, float]
    height: float
    units: str = DEFAULT_UNITS

    @property
    def description(self) -> str:
        """One line for a file header: what is exact and the approximation's tolerance."""
        return approximation_note(self.approximation, self.units)


def approximation_note(approximation: float, units: str = DEFAULT_UNITS) -> str:
    """The STEP description of a G2 solid whose non-exact surfaces deviate ``approximation`` from the exact ones."""
    if approximation == 0.0:
        return "spiral_cad G2 solid: every surface exact (extrusions, surfaces of revolution, planes)"
    return (
        f"spiral_cad G2 solid: sweeps over spirals approximated within {approximation:.3g} {units} "
        "of the exact sweep; all other surfaces exact"
    )


# ------------------------------------------------------------------ input and fit


def outline_segments(outline: Any, *, corners: bool = False) -> list[Segment]:
    """The plane segments of a closed outline: a ``Chain``, a ``FilletedPath``, an object with ``.filleted``
    (the continuous sketches) or segments in travel order; tangent at every joint unless ``corners``
    (an outline left sharp, whose walls meet at its corners).

    Raises:
        ValueError: anything else, segments in space, an outline that does not close, or a corner.
    """
    source = getattr(outline, "filleted", outline)
    source = getattr(source, "segments", source)
    if isinstance(source, Chain):
        source = list(source)
    if not isinstance(source, Sequence) or not source or not all(isinstance(s, Segment) for s in source):
        raise ValueError(f"outline must be a closed Chain, a FilletedPath or segments in travel order; got {type(outline).__name__}")
    segments = list(source)
    if any(s.dim != 2 for s in segments):
        raise ValueError("outline must lie in the plane (2-D segments)")
    size = max(float(np.ptp(np.vstack([s.point(np.linspace(0, 1, 5)) for s in segments]), axis=0).max()), 1e-300)
    gap = math.dist(segments[-1].end[:2], segments[0].start[:2])
    if gap > 1e-9 * size:
        raise ValueError(f"outline must be closed; its end is {gap:.3g} from its start")
    for index, (a, b) in enumerate(zip(segments, [*segments[1:], segments[0]]) if not corners else ()):
        (x, y, tx0, ty0, _), (_, _, tx1, ty1, _) = a.ends[1], b.ends[0]
        turn = abs(math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1))
        if turn > _CORNER_TOL:
            raise ValueError(
                f"outline must be tangent at every joint (a roll cannot follow a corner); the joint after segment "
                f"{index} at ({x:.6g}, {y:.6g}) turns {turn:.3g} rad: round it first (g2_fillet, fillet_path)"
            )
    return segments


def _inward(segments: list[Segment]) -> float:
    """+1 when the outline runs counterclockwise (its inward normal is the left one), else −1."""
    return 1.0 if _signed_area(_samples(segments)[0]) > 0.0 else -1.0


def _reverse(segments: list[Segment]) -> list[Segment]:
    return [s.reversed() for s in reversed(segments)]


def _loops(segments: list[Segment], holes: Sequence[list[Segment]] = ()) -> list[list[Segment]]:
    """The outline counterclockwise and each hole clockwise: the material on every loop's left."""
    outer = segments if _inward(segments) > 0.0 else _reverse(segments)
    return [outer] + [h if _inward(h) < 0.0 else _reverse(h) for h in holes]


def _rim(index: int) -> str:
    return "the outline's rim" if index == 0 else f"hole {index - 1}'s rim"


def _placement_problem(loops: list[list[Segment]], widths: Sequence[float]) -> tuple[int, int, NDArray] | None:
    """Loops ``i``, ``j`` whose inner offsets by ``widths`` cross or nest wrongly (a hole outside the
    outline, or inside another hole), with a point there; None when every loop keeps its place."""
    offsets = []
    for loop, width in zip(loops, widths):
        points, normals, _ = _samples(loop)
        offsets.append(points + width * normals)
    for i in range(len(loops)):
        for j in range(i + 1, len(loops)):
            place = _between(offsets[i], offsets[j])
            if place is not None:
                return i, j, place
            if (i == 0) != _inside(offsets[j][0], offsets[i]):
                return i, j, offsets[j][0]
            if i > 0 and _inside(offsets[i][0], offsets[j]):  # a hole inside a later one
                return i, j, offsets[i][0]
    return None


def _roll_problem(segments: list[Segment], height: float, edge_radius: Any, given_height: Any, name: str,
                  holes: Sequence[list[Segment]] = (), rolled: Sequence[tuple[bool, bool]] | None = None,
                  at: Callable[[float, float], str] = _plain,
                  **options: Any) -> str | None:  # fmt: skip
    """Why rolls of ``edge_radius`` (``options``: top, bottom, profile, transition, shape) do not fit the
    outline, its ``holes`` (``rolled``: each loop's top and bottom flags) and the height, or None."""
    top, bottom = options.pop("top"), options.pop("bottom")
    reach = float(roll_profile(float(edge_radius), **options)[-1].end[0])
    loops = _loops(segments, holes)
    flags = list(rolled) if rolled is not None else [(top, bottom)] * len(loops)
    widths = []
    for index, (loop_top, loop_bottom) in enumerate(flags):
        d_top, d_bottom = (reach if loop_top else 0.0), (reach if loop_bottom else 0.0)
        if d_top + d_bottom > height * (1.0 + _FIT_SLACK):
            where = "" if not holes else f" at {_rim(index)}"
            return (
                f"{name} {shown(edge_radius)} gives rolls {reach:.6g} high{where}; "
                f"{'together they' if loop_top and loop_bottom else 'it'} exceed height {shown(given_height)}"
            )
        widths.append(min(max(d_top, d_bottom), height))
    for index, (loop, width) in enumerate(zip(loops, widths)):
        if width == 0.0:
            continue
        problem = _fit_problem(loop, 1.0, width, edge_radius, name, at)
        if problem is not None:
            return problem if not holes else f"{problem} ({_rim(index)})"
    walls = [Wall(loop, 0.0, height, width, name=_rim(index)) for index, (loop, width) in enumerate(zip(loops, widths))]
    return meeting_problem(walls, edge_radius, name, lambda x, y, z: at(x, y)) if len(loops) > 1 else None


# ------------------------------------------------------------------ the solid


def forward_solid(solid: TopoDS_Shape) -> TopoDS_Solid:
    """The solid FORWARD: the same volume, usable in booleans.

    ``BRepLib.OrientClosedSolid`` and ``Reversed`` may leave a solid REVERSED with a positive
    volume; a fuse of a compound holding such a solid drops it (CadQuery's ``combine``). The
    solid is made again from its shells as they face (orientations composed down from it)."""
    if solid.Orientation() == TopAbs_FORWARD:
        return TopoDS.Solid_s(solid)
    maker = BRepBuilderAPI_MakeSolid()
    shells = TopExp_Explorer(solid, TopAbs_SHELL)
    while shells.More():
        maker.Add(TopoDS.Shell_s(shells.Current()))
        shells.Next()
    return maker.Solid()


def verify_solid(shape: TopoDS_Shape, what: str = "slab", facing_out: bool = False) -> None:
    """NoSolutionError unless ``shape`` is one valid, closed, FORWARD solid with positive volume
    (``BRepCheck_Analyzer``, which also finds a shell whose faces do not all face the same way;
    ``facing_out``: the caller knows the shell faces out, so its volume is positive, unmeasured)."""
    solids = TopExp_Explorer(shape, TopAbs_SOLID)
    count = 0
    while solids.More():
        count += 1
        solids.Next()
    if count != 1:
        raise NoSolutionError(f"the {what} is {count} solids, not one")
    if _first_solid(shape).Orientation() != TopAbs_FORWARD:
        raise NoSolutionError(f"the {what} is a {_first_solid(shape).Orientation().name} solid, not FORWARD (booleans drop it)")
    if not BRepCheck_Analyzer(shape, True, True).IsValid():  # geometry too, in parallel
        raise NoSolutionError(f"the {what} is not a valid solid (BRepCheck_Analyzer)")
    volume = 1.0 if facing_out else _volume(shape)
    if not volume > 0.0:
        raise NoSolutionError(f"the {what} encloses no volume ({volume:.3g})")


def continuous_box(
    length: float,
    width: float,
    height: float,
    radius: float,
    edge_radius: float | None = None,
    *,
    transition: float = 0.5,
    shape: str = DEFAULT_SHAPE,
    profile: str = "g2",
    top: bool = True,
    bottom: bool = True,
    tolerance: float | None = None,
    units: str = DEFAULT_UNITS,
    holes: Sequence[Any] = (),
    _advise: bool = True,
) -> Slab:
    """A box with every edge and corner G2: ``rolled_slab`` of a ``continuous_rectangle`` (centred on the origin,
    z from 0 to ``height``). ``edge_radius`` None: the roll half as wide as the smaller of ``radius`` and
    ``height``/2 allows; ``holes``: through holes in the box's plan, centred like it. Other arguments and
    errors as ``rolled_slab`` and ``continuous_rectangle``."""
    for value, name in ((length, "length"), (width, "width"), (height, "height")):
        if not as_float(value, name) > 0.0:
            raise ValueError(f"{name} must be positive; got {shown(value)}")
    try:
        plan = continuous_rectangle(length, width, radius, transition, units=units, shape=shape)
    except NoSolutionError as error:
        if not _advise:
            raise
        raise _plan_refusal(error, length, width, height, as_float(radius, "radius"), edge_radius,
                            dict(transition=transition, shape=shape, profile=profile, top=top, bottom=bottom, holes=holes),
                            tolerance, units) from None  # fmt: skip
    if edge_radius is None:  # the roll's extent is proportional to its radius
        unit = float(roll_profile(1.0, profile=profile, transition=transition, shape=shape)[-1].end[0])
        edge_radius = 0.5 * min(as_float(radius, "radius"), as_float(height, "height") / 2.0) / unit
    return rolled_slab(plan, height, edge_radius, top=top, bottom=bottom, profile=profile, transition=transition,
                   shape=shape, tolerance=tolerance, units=units, holes=holes, _advise=_advise)  # fmt: skip


def _plan_refusal(error: NoSolutionError, length: float, width: float, height: float, radius: float,
                  edge_radius: float | None, options: dict[str, Any], tolerance: float | None,
                  units: str) -> NoSolutionError:  # fmt: skip
    """The refusal of plan corners too large for the box, with the largest ``radius`` that fits and builds
    (with the given ``edge_radius``); when that roll fits no plan radius that fits, the largest plan radius
    and the largest roll it holds, built together."""
    transition, shape = options["transition"], options["shape"]

    def plan_fits(r: float) -> bool:  # shrinking corners only ever fit better
        try:
            continuous_rectangle(length, width, r, transition, shape=shape)
        except NoSolutionError:
            return False
        return True

    def box(r: float) -> Slab:
        return continuous_box(length, width, height, r, edge_radius, **options, tolerance=tolerance, units=units,
                              _advise=False)  # fmt: skip

    problem = f"{error} (the plan corners)"
    fits = advice(plan_fits, box, radius)
    if fits is not None or edge_radius is None:
        return refusal(problem, "radius", fits)
    corner = advice(plan_fits, lambda r: continuous_rectangle(length, width, r, transition, shape=shape), radius)
    problem += f"; no radius fits with edge_radius {shown(edge_radius)}"
    if corner is None:
        return refusal(problem, "radius", None)
    plan = outline_segments(continuous_rectangle(length, width, corner, transition, shape=shape))
    slab_options = dict(options, profile=options["profile"])
    roll = _slab_advice(plan, height, as_float(edge_radius, "edge_radius"), height, "edge_radius", slab_options,
                        tolerance, units)  # fmt: skip
    if roll is None:
        return refusal(problem, "radius", None)
    return NoSolutionError(f"{problem}; with radius {corner:.6g}, edge_radius up to {roll:.6g} fits")


def expected_level(segments: Sequence[Segment], profile: str = "g2") -> str:
    """The continuity the construction promises for tangent edges: ``"G2"`` for a G2 profile along an
    outline whose tangent joints are all G2, else ``"G1"`` (circular profiles, circularly filleted outlines)."""
    if profile != "g2":
        return "G1"
    for index, (a, b) in enumerate(zip(segments, [*segments[1:], segments[0]])):
        if not _turns(a, b) and g2_mismatch(a, b, JOIN_TOLERANCE, index=index) is not None:
            return "G1"
    return "G2"


def verify_faces(shape: TopoDS_Shape, level: str, what: str = "slab", units: str = DEFAULT_UNITS) -> None:
    """NoSolutionError unless the face checker (``spiral_cad.cad.faces.check_faces``, default tolerances:
    normals ≤ 1e-7 rad, normal-curvature jump ≤ 1e-4 relative, gaps ≤ twice the edges' tolerances) finds every tangent
    edge at least ``level`` and no gap; sharp edges are features, listed there and not failed."""
    from .faces import check_faces  # late: the checker reads files through this layer's readers

    report = check_faces(shape, units=units)
    if report.passes(level):
        return
    worst = min(report.edges, key=lambda e: (e.level == "sharp", e.level == level, -e.jump, -e.angle))
    raise NoSolutionError(
        f"the {what} is refused: the face checker finds edge {worst.index} ({worst.surfaces[0]}–{worst.surfaces[1]}) "
        f"{worst.level}, not {level} (gap {worst.gap:.3g}, normal angle {worst.angle:.3g} rad, relative curvature "
        f"jump {worst.jump:.3g} at {worst.jump_at}); {report.describe()}"
    )


def rolled_slab(
    outline: Any,
    height: float,
    edge_radius: float,
    *,
    top: bool = True,
    bottom: bool = True,
    profile: str = "g2",
    transition: float = 0.5,
    shape: str = DEFAULT_SHAPE,
    tolerance: float | None = None,
    units: str = DEFAULT_UNITS,
    holes: Sequence[Any] = (),
    _rolled: Sequence[tuple[bool, bool]] | None = None,
    _at: Callable[[float, float], str] = _plain,
    _verify: bool = True,
    _name: str = "edge_radius",
    _advise: bool = True,
) -> Slab:
    """A closed planar outline extruded by ``height`` with its top and bottom edges rolled (see the module docstring).

    Args:
        outline: a closed plane ``Chain`` of lines, arcs and spirals (G2 for a
            G2 solid; tangent joints are swept as they are), a ``FilletedPath``
            (``continuous_rectangle`` …) or its segments; convex or concave,
            either sense. It lies in z = 0; the slab rises to z = ``height``.
        height: the slab's height (> 0).
        edge_radius: the roll profile's smallest radius of curvature (> 0).
        top, bottom: roll the top / bottom edge (else the edge stays sharp).
        profile: ``"g2"`` or ``"circular"`` (``roll_profile``).
        transition, shape: of the G2 profile's spirals.
        tolerance: the largest deviation allowed for the sweep over a spiral
            (default 1e-7 × the outline's size).
        units: the unit of the numbers (kept for the files written).
        holes: closed outlines inside ``outline`` (as ``outline``, either
            sense), through holes of the slab: each hole's rim is rolled with
            the same profile, turning the other way (concave in plan), top and
            bottom as ``top`` and ``bottom`` say.

    Returns:
        The ``Slab``: the solid and the measured approximation. It is verified as returned: one valid
        closed solid (``BRepCheck_Analyzer``), and the face checker finds every edge G2 (G1 for a
        circular profile or an outline with G1 joints) or a sharp feature (unrolled edges).

    Raises:
        ValueError: malformed input.
        NoSolutionError: the roll does not fit (it is as wide as it is high:
            wider than the outline's smallest convex radius of curvature, an
            inner offset that crosses itself, the rolls of two rims meeting
            across a wall thinner than both, or both rolls higher than
            ``height``) — the message names the value and what would fit.
    """
    units = length_unit(units)
    if _rolled is not None and len(_rolled) != 1 + len(holes):
        raise ValueError(f"_rolled needs one (top, bottom) pair per loop; got {len(_rolled)} for {1 + len(holes)}")
    sharp = [not any(f) for f in _rolled] if _rolled is not None else [not (top or bottom)] * (1 + len(holes))
    segments = outline_segments(outline, corners=sharp[0])
    hole_loops = [outline_segments(h, corners=c) for h, c in zip(holes, sharp[1:])]
    if hole_loops and (misplaced := _placement_problem(_loops(segments, hole_loops), [0.0] * (1 + len(hole_loops)))):
        i, j, place = misplaced
        raise ValueError(
            f"holes must lie inside the outline and apart from each other; {_rim(i)} and {_rim(j)} cross or nest "
            f"near ({place[0]:.6g}, {place[1]:.6g})"
        )
    given_height, height = height, as_float(height, "height")
    if not height > 0.0:
        raise ValueError(f"height must be positive; got {shown(height)}")
    options: dict[str, Any] = dict(top=top, bottom=bottom, profile=profile, transition=transition, shape=shape,
                                   holes=hole_loops, rolled=_rolled, at=_at)  # fmt: skip
    radius = as_float(edge_radius, "edge_radius")
    problem = _roll_problem(segments, height, edge_radius, given_height, _name, **options)
    options["verify"] = _verify
    if problem is not None:
        if not _advise:
            raise NoSolutionError(problem)
        raise refusal(problem, _name, _slab_advice(segments, height, radius, given_height, _name, options, tolerance, units))
    try:
        return _built_slab(segments, height, edge_radius, options, tolerance, units)
    except NoSolutionError as error:  # fits, yet does not build: nearly singular (rolls meeting, an offset folding)
        if not _advise:
            raise
        raise refusal(str(error), _name, _slab_advice(segments, height, radius, given_height, _name, options, tolerance, units)) from None


def _slab_advice(segments: list[Segment], height: float, radius: float, given_height: Any, name: str,
                 options: dict[str, Any], tolerance: float | None, units: str) -> float | None:  # fmt: skip
    """The largest roll radius below ``radius`` a refusal may name: it fits with a margin and builds."""
    return advice(
        lambda r: _roll_problem(segments, height, r, given_height, name, **_fit_options(options)) is None,
        lambda r: rolled_slab(segments, height, r, **_slab_options(options), tolerance=tolerance, units=units, _advise=False),
        radius,
    )


def _slab_options(options: dict[str, Any]) -> dict[str, Any]:
    """``rolled_slab``'s keyword arguments from the fit checks' ``options``."""
    rest = {k: v for k, v in options.items() if k not in ("holes", "rolled", "at", "verify")}
    return dict(rest, holes=options.get("holes", ()), _rolled=options.get("rolled"), _at=options.get("at", _plain))


def _fit_options(options: dict[str, Any]) -> dict[str, Any]:
    """The fit checks' ``options`` without what only the construction reads."""
    return {k: v for k, v in options.items() if k != "verify"}


def _built_slab(segments: list[Segment], height: float, edge_radius: float, options: dict[str, Any],
                tolerance: float | None, units: str) -> Slab:  # fmt: skip
    """The slab of rolls that fit, verified (``rolled_slab`` after its fit checks)."""
    top, bottom, profile, transition, shape = (options[k] for k in ("top", "bottom", "profile", "transition", "shape"))
    loops = _loops(segments, options.get("holes", ()))
    flags = options.get("rolled") or [(top, bottom)] * len(loops)
    roll = roll_profile(edge_radius, profile=profile, transition=transition, shape=shape)
    reach = float(roll[-1].end[0])
    points, _, _ = _samples(segments)
    size = float(np.ptp(points, axis=0).max())
    tol = 1e-7 * size if tolerance is None else as_float(tolerance, "tolerance")
    if not tol > 0.0:
        raise ValueError(f"tolerance must be positive; got {shown(tolerance)}")
    walls = [Wall(loop, 0.0, height, reach if loop_top else 0.0, reach if loop_bottom else 0.0, name=_rim(index))
             for index, (loop, (loop_top, loop_bottom)) in enumerate(zip(loops, flags))]  # fmt: skip
    solid, approximation = stack_solid(walls, roll, tol, size)
    reaches = tuple(min(max((getattr(w, side) for w in walls), default=0.0), height) for side in ("top", "bottom"))
    if options.get("verify", True):  # a caller that moves the solid verifies it where it is returned
        verify_solid(solid, facing_out=True)
        levels = [expected_level(loop, profile) for loop in loops]
        verify_faces(solid, "G1" if "G1" in levels else "G2", units=units)
    return Slab(solid, approximation, (reaches[0], reaches[1]), height, units)


def _volume(shape: TopoDS_Shape) -> float:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def _first_solid(shape: TopoDS_Shape) -> TopoDS_Solid:
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    return TopoDS.Solid_s(explorer.Current())


def _turns(before: Segment, after: Segment) -> bool:
    """Whether the outline turns (a sharp corner) from ``before`` into ``after`` (tangent joints are left alone)."""
    (tx0, ty0), (tx1, ty1) = before.ends[1][2:4], after.ends[0][2:4]
    return abs(math.atan2(tx0 * ty1 - ty0 * tx1, tx0 * tx1 + ty0 * ty1)) > TANGENT_TOL
