"""G2 fillets of build123d wires, faces and 2.5-D parts, and G2 slabs and boxes (``spiral_cad.build123d``)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from build123d import (
    Align,
    BasePartObject,
    Builder,
    BuildPart,
    Compound,
    Curve,
    Edge,
    Face,
    Location,
    Mode,
    Part,
    RotationLike,
    Shape,
    Sketch,
    Solid,
    Vector,
    Vertex,
    Wire,
    flatten_sequence,
)
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GeomAbs import GeomAbs_CurveType
from OCP.gp import gp_Ax3
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopoDS import TopoDS

from ..cad.fillet import fillet_face, fillet_wire, planar_frame
from ..cad.occ import chain_wire
from ..cad.slabs import Slab, continuous_box
from ..cad.slabs import rolled_slab as _slab
from ..cad.stack_fillet import fillet_part_edges
from ..core.segments import Segment
from ..core.shapes import DEFAULT_SHAPE
from ..design.rounded_paths import fillet_polyline


def _points(vertices) -> list[tuple[float, float, float]] | None:
    if vertices is None:
        return None
    items = [vertices] if isinstance(vertices, Vertex) else list(vertices)
    for item in items:
        if not isinstance(item, Vertex):
            raise ValueError(f"vertices must be build123d Vertex objects; got {type(item).__name__}")
    return [tuple(Vector(v)) for v in items]


def g2_fillet(
    target: Wire | Face | Sketch | Curve | Vertex | Iterable[Vertex] | Edge | Iterable[Edge],
    radius: float,
    vertices: Iterable[Vertex] | None = None,
    transition: float = 0.5,
    same_sense: str = "nested",
    shape: str = DEFAULT_SHAPE,
) -> Wire | Face | Sketch | Curve | Part:
    """Operation: G2 Fillet

    Round corners with curvature-continuous fillets ("continuous corners"):
    each corner becomes transition → arc of ``radius`` → transition, joined G2
    on both sides (``spiral_cad.design.fillets``), with exact LINE, CIRCLE and
    BEZIER edges and a G2 closing joint.

    Used like build123d's ``fillet``: given a planar ``Wire``, ``Face``,
    ``Sketch`` or ``Curve`` (on any plane) it returns the same kind with the
    chosen corners (default: all) rounded, every wire and every face of it;
    inside ``BuildSketch``/``BuildLine``, given vertices (e.g.
    ``sketch.vertices()``), it rounds those vertices of the builder's object
    and replaces it (``Mode.REPLACE``).

    Given straight edges of a solid (``part.edges().filter_by(Axis.Z)``), as
    build123d's ``fillet`` takes them, it returns the part rounded G2: side
    edges of a right prism (between two planar faces, any dihedral angle,
    convex or concave, each end meeting a cap perpendicular to it) become
    exact extrusions of the 2-D G2 corner; when every edge of a cap is chosen
    too, the cap's edge is rolled by the G2 profile of the same radius
    (``g2_slab``); a cap's holes (a plate drilled through) are rims of their
    own, rolled the other way, each chosen whole or left sharp. Side and cap
    edges chosen together (``box.edges()``) get one radius as the smallest
    radius of curvature of every edge: the rolls
    are of ``radius`` and the side corners of ``plan_radius(radius)`` (1.25 ×
    the roll's reach, 1.571 × radius), wide enough to hold the roll. A 2.5-D
    part — a stack of prisms along one axis: pockets with floors, bosses,
    steps, counterbores — is rounded the same way wall by wall; a rim where a
    face rises on the open side (a pocket's floor, the face a boss stands on)
    gets the roll turned over, a concave G2 fillet. Inside ``BuildPart`` the
    builder's part is replaced.

    Args:
        target: the shape to round, the vertices to round in a builder, or
            the edges of a part to round.
        radius (float): the smallest radius of curvature in each corner.
        vertices (Iterable[Vertex], optional): corners to round; default all.
        transition (float, optional): share of each corner's turn made by the
            transitions, in (0, 1]; 1 gives a spiral pair with no arc. Defaults to 0.5
        same_sense (str, optional): ``"nested"`` or ``"C"`` for an arc that
            turns the same way as its corner. Defaults to "nested"
        shape (str, optional): spiral shape of the transitions, "walton-meek" or
            "near-linear" (curvature almost linear in arc length). Defaults to "walton-meek"

    Raises:
        ValueError: a solid or shell itself (give its edges, ``part.edges()``, or one
            of its faces), non-planar input, edges other than lines
            and arcs, or edges that belong to no wire or face.
        NoSolutionError: a corner that cannot be rounded (named, with numbers);
            solid edges that are not a 2.5-D part's vertical edges or whole rims of its walls (outline,
            hole, pocket, boss), rolls meeting across thin material, a face neither horizontal nor vertical,
            walls of different heights meeting on one rim (a slot reaching the side) — named by edge and
            point, with the largest radius that builds where one does.
    """
    context: Builder | None = Builder._get_context("g2_fillet")
    if isinstance(target, Iterable) and not isinstance(target, (Shape, str, bytes)):
        target = list(flatten_sequence(target))
        if not target:
            raise ValueError("g2_fillet got an empty list of edges (or vertices): there is nothing to round")
    edges = _solid_edges(target)
    if edges is not None:
        return _fillet_edges(edges, radius, context, transition=transition, same_sense=same_sense, shape=shape)
    in_builder = isinstance(target, Vertex) or (isinstance(target, Iterable) and not isinstance(target, (Shape, str, bytes)))
    if in_builder:
        _points(target)  # only vertices select corners of a builder's object
        if context is None or context._obj is None:
            raise ValueError("g2_fillet of vertices needs a BuildSketch or BuildLine with an object")
        vertices, target = target, context._obj
    points = _points(vertices)
    options: dict[str, Any] = dict(transition=transition, same_sense=same_sense, shape=shape)
    if not isinstance(target, Shape):
        raise ValueError(f"g2_fillet rounds a Wire, Face, Sketch or Curve; got {type(target).__name__}")
    solids = target.solids() or target.shells()
    if solids or getattr(target, "_dim", None) == 3:
        raise ValueError(
            f"g2_fillet rounds planar wires, faces and sketches, or a part's edges; got a {type(target).__name__} "
            f"with {len(target.solids())} solid(s) and {len(target.shells())} shell(s): give the edges to round, "
            f"g2_fillet(part.edges(), {radius!r}) (or some of them: part.edges().filter_by(Axis.Z)), or one of its faces"
        )
    in_space = _lines_in_space(target) if isinstance(target, Wire) else None
    if in_space is not None:
        corners, closed = in_space
        chosen = None if points is None else _corner_indices(corners, points)
        rounded = fillet_polyline(corners, radius, vertices=chosen, closed=closed, **options)
        result = Wire(chain_wire(rounded.segments))
    elif isinstance(target, Wire):
        result = Wire(fillet_wire(target.wrapped, radius, points, **options)[0])
    elif isinstance(target, Face) and not isinstance(target, Sketch):
        result = Face(fillet_face(target.wrapped, radius, points, **options))
    else:
        faces, wires = target.faces(), [] if target.faces() else target.wires()
        _refuse_loose_edges(target, faces or wires)
        if faces:
            result = Sketch(Compound([Face(fillet_face(f.wrapped, radius, points, **options)) for f in faces]).wrapped)
        else:  # one plane for all the wires (a straight wire alone has none; here it passes through)
            frame = planar_frame(target.wrapped)
            rounded_wires = [fillet_wire(w.wrapped, radius, points, frame=frame, **options)[0] for w in wires]
            result = Curve(Compound([Wire(w) for w in rounded_wires]).wrapped)
    if in_builder:
        assert context is not None  # checked above: vertices need a builder
        context._add_to_context(result, mode=Mode.REPLACE)
    return result


def _solid_edges(target: Any) -> list[Edge] | None:
    """The edges of ``target`` when it is an edge or edges (a solid's, for ``g2_fillet``), else None."""
    if isinstance(target, Edge):
        return [target]
    if isinstance(target, Iterable) and not isinstance(target, (Shape, str, bytes)):
        items = list(flatten_sequence(target))
        if items and all(isinstance(item, Edge) for item in items):
            return items
    return None


def _fillet_edges(edges: list[Edge], radius: float, context: Builder | None, **options: Any) -> Part:
    """``g2_fillet`` of a part's straight edges: the rounded part (the builder's part replaced in ``BuildPart``)."""
    part = context._obj if isinstance(context, BuildPart) else edges[0].topo_parent
    if part is None or not part.solids():
        raise ValueError("g2_fillet of edges needs edges of a part (from part.edges(), or inside BuildPart)")
    if len(part.solids()) != 1:
        raise ValueError(f"g2_fillet of edges rounds one solid; the part has {len(part.solids())}")
    slab = fillet_part_edges(part.solids()[0].wrapped, [e.wrapped for e in edges], radius, **options)
    result = _part(slab)
    if isinstance(context, BuildPart):
        context._add_to_context(result, mode=Mode.REPLACE)
    return result


def _part(slab: Slab) -> Part:
    """A ``Part`` of the slab's solid that carries its ``approximation`` (written into STEP descriptions)."""
    result = Part(Compound([Solid(slab.shape)]).wrapped)
    result.approximation = slab.approximation
    return result


def g2_slab(
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
) -> Part:
    """A closed G2 outline extruded along +z by ``height`` with its top and bottom edges rolled G2.

    The roll (line → spiral → arc → spiral → line in the vertical section,
    smallest radius of curvature ``edge_radius``) is swept along the outline:
    exact over its lines and arcs, over spirals within ``tolerance`` (the
    measured deviation is the part's ``approximation`` attribute and goes into
    the STEP description). See ``spiral_cad.cad.slabs.rolled_slab``.

    Args:
        outline: a ``ContinuousRectangle``/``ContinuousPolygon``/``ContinuousSlot``, a
            closed ``Chain``, a ``FilletedPath`` or segments (in the XY plane), or a
            planar face, one-face sketch or closed wire of lines, arcs and cubic Bézier
            spirals (``g2_fillet`` output; a builder's cubic B-spline edges are read as their Bézier spans) lying in the XY plane.
            A face's holes (inner wires) become through holes whose rims are rolled the same way.
        height: the part's height.
        edge_radius: the roll's smallest radius of curvature.
        top, bottom: roll the top / bottom edge. Default True.
        profile: ``"g2"`` or ``"circular"``. Default "g2".
        transition, shape: of the roll's spirals.
        tolerance: the largest deviation of a sweep over a spiral (default 1e-7 × size).

    Raises:
        ValueError: malformed input, or holes that cross the outline or each other.
        NoSolutionError: the roll does not fit (named, with what would fit).
    """
    if isinstance(outline, Sketch) and not hasattr(outline, "filleted"):
        if len(outline.faces()) != 1:
            raise ValueError(f"g2_slab takes a sketch of one face; this one has {len(outline.faces())}")
        outline = outline.faces()[0]
    face = isinstance(outline, Face) and not hasattr(outline, "filleted")
    holes = [_plane_outline(w) for w in outline.inner_wires()] if face else []
    outline = outline.outer_wire() if face else outline
    if isinstance(outline, (Face, Wire)) and not hasattr(outline, "filleted"):
        outline = _plane_outline(outline)
    slab = _slab(outline, height, edge_radius, top=top, bottom=bottom, profile=profile, transition=transition,
                 shape=shape, tolerance=tolerance, holes=holes)  # fmt: skip
    return _part(slab)


def _plane_outline(wire: Wire) -> list[Segment]:
    """A closed wire in the XY plane as segments."""
    from ..cad.fillet import wire_path

    if any(abs(v.Z) > 1e-9 * max(1.0, wire.bounding_box().diagonal) for v in wire.vertices()):
        raise ValueError("g2_slab takes an outline in the XY plane (z = 0)")
    segments, closed = wire_path(wire.wrapped, gp_Ax3(), spirals=True)
    if not closed:
        raise ValueError("g2_slab needs a closed outline")
    return segments


class ContinuousBox(BasePartObject):
    """Part Object: Continuous Box

    A box whose every edge and corner is curvature continuous (G2): the plan
    outline is a ``ContinuousRectangle`` (corners spiral → arc of ``radius``
    → spiral) and the top and bottom edges are rolled by a G2 profile
    (line → spiral → arc of ``edge_radius`` → spiral → line) swept along it
    (``g2_slab``). With ``profile="circular"`` the rolls are quarter circles.

    The sweep over the outline's spirals is approximated (a B-spline that
    meets the exact patches G2); the measured deviation is ``approximation``.

    Args:
        length (float): box length (x)
        width (float): box width (y)
        height (float): box height (z)
        radius (float): the plan corners' smallest radius of curvature
        edge_radius (float, optional): the rolled edges' smallest radius of curvature; None: the roll
            whose extent is half of the smaller of ``radius`` and ``height``/2. Defaults to None
        transition (float, optional): share of each turn made by spirals (plan and roll). Defaults to 0.5
        shape (str, optional): spiral shape, "walton-meek" or "near-linear". Defaults to "walton-meek"
        profile (str, optional): roll profile, "g2" or "circular". Defaults to "g2"
        top (bool, optional): roll the top edge. Defaults to True
        bottom (bool, optional): roll the bottom edge. Defaults to True
        tolerance (float, optional): largest deviation of the sweep over spirals; None: 1e-7 × size.
            Defaults to None
        holes (Iterable, optional): through holes: closed plane outlines (a ``Chain``, a continuous
            sketch, segments such as ``[Arc((x, y), r, 0, 2π)]``) in the box's plan, centred on the
            box; each rim rolled like the outline's, turning the other way (``g2_slab``). Defaults to ()
        rotation (RotationLike, optional): angles to rotate about axes. Defaults to (0, 0, 0)
        align (Align | tuple[Align, Align, Align] | None, optional): align MIN, CENTER,
            or MAX of object. Defaults to (Align.CENTER, Align.CENTER, Align.CENTER)
        mode (Mode, optional): combine mode. Defaults to Mode.ADD

    Raises:
        ValueError: malformed input (a hole crossing the outline or another hole).
        NoSolutionError: plan corners or rolls that do not fit (named, with what would fit).
    """

    _applies_to = [BuildPart._tag]

    def __init__(self, length: float, width: float, height: float, radius: float, edge_radius: float | None = None,
                 transition: float = 0.5, shape: str = DEFAULT_SHAPE, profile: str = "g2", top: bool = True,
                 bottom: bool = True, tolerance: float | None = None, holes: Iterable[Any] = (),
                 rotation: RotationLike = (0, 0, 0),
                 align: Align | tuple[Align, Align, Align] | None = (Align.CENTER, Align.CENTER, Align.CENTER),
                 mode: Mode = Mode.ADD):  # fmt: skip
        self.length, self.width, self.box_height = length, width, height
        self.slab = continuous_box(length, width, height, radius, edge_radius, transition=transition, shape=shape,
                                   profile=profile, top=top, bottom=bottom, tolerance=tolerance, holes=list(holes))  # fmt: skip
        self.approximation = self.slab.approximation
        solid = Solid(self.slab.shape)
        if align is not None:  # the box's extent is known: OCCT's optimal bounding box of the sweeps costs seconds
            aligns = (align,) * 3 if isinstance(align, Align) else tuple(align)
            low, high = (-length / 2.0, -width / 2.0, 0.0), (length / 2.0, width / 2.0, height)
            offset = [{Align.MIN: -lo, Align.CENTER: -(lo + hi) / 2.0, Align.MAX: -hi, Align.NONE: 0.0}[a]
                      for a, lo, hi in zip(aligns, low, high)]  # fmt: skip
            solid = solid.moved(Location(offset))
        super().__init__(part=solid, rotation=rotation, align=None, mode=mode)


def _lines_in_space(wire: Wire) -> tuple[list[tuple[float, float, float]], bool] | None:
    """The vertices (in travel order) and closedness of a wire of lines that does not lie in one
    plane; None for a planar wire or one with other edges (the planar fillet handles those)."""
    try:
        planar_frame(wire.wrapped)
        return None
    except ValueError:
        pass
    points = []
    explorer = BRepTools_WireExplorer(wire.wrapped)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        curve = BRepAdaptor_Curve(edge)
        if curve.GetType() != GeomAbs_CurveType.GeomAbs_Line:
            return None
        first, last = curve.FirstParameter(), curve.LastParameter()
        start = curve.Value(last if edge.Orientation() == TopAbs_REVERSED else first)
        points.append((start.X(), start.Y(), start.Z()))
        end = curve.Value(first if edge.Orientation() == TopAbs_REVERSED else last)
        explorer.Next()
    if len(points) < 2:
        return None
    closed = wire.is_closed
    if not closed:
        points.append((end.X(), end.Y(), end.Z()))
    return points, closed


def _corner_indices(corners: list[tuple[float, float, float]], points: list[tuple[float, float, float]]) -> list[int]:
    """Indices of the polyline vertices at the chosen build123d vertices (others are ignored, as in the plane)."""
    size = max(max(abs(c) for c in p) for p in corners)
    chosen = []
    for point in points:
        for i, corner in enumerate(corners):
            if max(abs(a - b) for a, b in zip(point, corner)) <= 1e-7 * max(size, 1.0):
                chosen.append(i)
    return chosen


def _refuse_loose_edges(target: Shape, parts: list[Shape]) -> None:
    """ValueError unless every edge of ``target`` belongs to one of ``parts`` (its faces or its wires)."""
    held = sum(len(p.edges()) for p in parts)
    edges = len(target.edges())
    if not parts or held < edges:
        what = "faces" if parts and isinstance(parts[0], Face) else "wires"
        raise ValueError(
            f"g2_fillet rounds whole wires and faces; this {type(target).__name__} has {edges - held} of its "
            f"{edges} edge(s) outside its {what}"
        )
