"""STEP and IGES files read by OCCT in a child process: whole, every curve accounted for, in their unit.

OCCT's readers are native code that a damaged or hostile file can crash,
hang or make exhaust memory, so they never run in the calling process: the
file is read in a forked child (``spiral_cad.cad.sandbox``: time and memory
limits) which sends back plain data — the shape in OCCT's binary BRep form
for ``read_shape``, the measured end frames of every edge for the checker.
A failure of any kind is a ``ReadError`` (a ``ValueError``) naming the file;
the caller lives on.

A file is accepted only if it was read whole:

* the reader's own verdict: a syntax error, a truncated file (no end
  section), entities that failed to load, roots that could not be
  transferred;
* an IGES file's sections must agree with its terminate record (checked
  before OCCT sees it);
* **every curve is accounted for**: the curve entities that must each become
  an edge — every ``EDGE_CURVE`` (of a ``CONNECTED_EDGE_SET`` or a face),
  every segment of a ``COMPOSITE_CURVE`` and every other curve of a
  ``GEOMETRIC_(CURVE_)SET`` in STEP; every leaf of an independent curve
  entity in IGES (the members of a composite curve 102, and lines, arcs,
  conics, splines, offset curves) — are counted and compared with the edges
  transferred, and every edge must span a finite parameter range (OCCT
  found its vertices on its curve). A file of 7 curves read as 6 edges is
  refused, naming the curve that was dropped and why; so is a root the
  reader could not transfer, with the curves it could not translate.

Units: with ``units=None`` a file is read in the length unit it declares (a
STEP ``GLOBAL_UNIT_ASSIGNED_CONTEXT``, the IGES global section) with no
conversion, if it is one spiral_cad names (mm, cm, m, km, in, ft; others —
micrometres, miles — are converted to millimetres); a unit name converts to
that unit, as build123d and FreeCAD read (millimetres). The unit read in is
returned with the data.
"""

from __future__ import annotations

import importlib
import io
import math
import os
import re
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache
from pathlib import Path
from typing import Any, cast

from OCP.BRep import BRep_Tool
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Shape
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..core.units import MM_PER_UNIT, length_unit
from .console import captured_messages
from .sandbox import Isolated

__all__ = ["IGES_SUFFIXES", "STEP_SUFFIXES", "ReadError", "read_file", "read_shape"]

STEP_SUFFIXES = (".step", ".stp")
IGES_SUFFIXES = (".iges", ".igs")
#: IGES entity types that are curves (106: copious data, only its curve forms).
_IGES_CURVES = {100, 102, 104, 106, 110, 112, 126, 130}
_IGES_POLYLINE_FORMS = {11, 12, 13, 63}
#: Composite curves nested deeper than this are refused (a composite that contains itself).
_MAX_NESTING = 64
#: Stands for the curve found at that depth.
_NESTED = object()


class ReadError(ValueError):
    """A STEP/IGES file that the reader rejected, could not read whole, or crashed on; the message gives the reason."""


def read_shape(path: str | os.PathLike, units: str | None = "mm") -> TopoDS_Shape:
    """Read a STEP (.step/.stp) or IGES (.igs/.iges) file into one shape.

    The file is read in a child process (see the module docstring) and the
    shape handed over in OCCT's binary BRep form: solids, faces and wires
    arrive as the reader made them.

    Args:
        path: the file.
        units: the unit of the returned shape (default mm, as build123d and
            FreeCAD read); None: the unit the file declares, unconverted.

    Raises:
        ReadError: the reader failed, crashed, ran out of time or memory,
            reported failed entities or dropped a curve.
        ValueError: unknown suffix, missing file or unknown ``units``.
    """
    from OCP.BinTools import BinTools

    _, data = read_file(path, units, _shape_bytes)
    shape = TopoDS_Shape()
    BinTools.Read_s(shape, io.BytesIO(data))
    return shape


def _shape_bytes(shape: TopoDS_Shape) -> bytes:
    from OCP.BinTools import BinTools

    buffer = io.BytesIO()
    BinTools.Write_s(shape, buffer)
    return buffer.getvalue()


def read_file(path: str | os.PathLike, units: str | None, extract: Callable[..., Any], *, stated: bool = False) -> tuple[str, Any]:
    """Read a STEP/IGES file in a child process and return ``(unit, extract(shape))``.

    ``extract`` runs in the child on the shape read (so evaluating its curves
    cannot harm the caller either) and must return plain data (``marshal``).
    ``unit`` is the unit the shape was read in: ``units``, or with None the
    unit the file declares (``"m"``), or ``"mm"`` for a unit spiral_cad does
    not name. With ``stated``, ``extract(shape, uncertainty)`` is called with
    the precision the file states (STEP's ``UNCERTAINTY_MEASURE_WITH_UNIT``,
    IGES's minimum resolution), in the unit read in; 0.0 when it states none.

    Raises:
        ReadError, ValueError: as ``read_shape``.
    """
    with start_reading(path, units, extract, stated=stated) as child:
        return finish_reading(child)


def start_reading(path: str | os.PathLike, units: str | None, extract: Callable[..., Any], *, stated: bool = False) -> Isolated:
    """``read_file`` started: the child reads while the caller goes on; ``finish_reading`` waits.

    Raises:
        ValueError: a path that is not a readable STEP/IGES file (checked here, before the child starts).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if units is not None:
        length_unit(units)
    if suffix not in STEP_SUFFIXES + IGES_SUFFIXES:
        raise ValueError(f"cannot read {p.name!r}: expected a .step/.stp or .igs/.iges file")
    if not p.is_file():
        raise ValueError(f"cannot read {str(p)!r}: " + ("not a regular file" if p.exists() else "no such file"))
    kind = "STEP" if suffix in STEP_SUFFIXES else "IGES"
    if kind == "IGES":
        _check_iges_sections(p)
    _load_readers()
    return Isolated(_read_and_extract, p, kind, units, extract, stated, what=f"the {kind} reader", subject=p.name)


def finish_reading(child: Isolated) -> tuple[str, Any]:
    """The ``(unit, extract(shape))`` of a ``start_reading`` child, once it is there."""
    try:
        return child.result()
    except ValueError as error:  # the child's ReadError, or the reader's crash, timeout, exhaustion
        raise ReadError(str(error)) from None


@cache
def _load_readers() -> None:
    """Import and initialise OCCT's reader modules here, once, so that no child pays for it (~50 ms)."""
    for name in ("BinTools", "BRepAdaptor", "IFSelect", "IGESControl", "IGESToBRep", "STEPConstruct", "STEPControl",
                 "StepData", "StepGeom", "StepRepr", "StepShape", "StepToGeom"):  # fmt: skip
        importlib.import_module(f"OCP.{name}")
    from OCP.IGESControl import IGESControl_Controller
    from OCP.STEPControl import STEPControl_Controller

    STEPControl_Controller.Init_s()
    IGESControl_Controller.Init_s()


def _read_and_extract(path: Path, kind: str, units: str | None, extract: Callable[..., Any], stated: bool = False) -> tuple[str, Any]:
    """The child's work: read the file whole, then extract what the caller needs."""
    precision: list[float] = []
    shape, unit = _read_whole(path, kind, units, precision)
    return unit, (extract(shape, precision[0] if precision else 0.0) if stated else extract(shape))


@contextmanager
def _utf8_name(path: Path) -> Iterator[str]:
    """A name of ``path`` that OCCT's readers take (UTF-8): the path itself, or for a name of other
    bytes (``caf\xe9.step`` in Latin-1) a symbolic link to it in a temporary folder."""
    name = str(path)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        with tempfile.TemporaryDirectory(prefix="spiral-cad-read-") as folder:
            link = os.path.join(folder, f"input{path.suffix.encode('ascii', 'replace').decode()}")
            os.symlink(os.path.abspath(path), link)
            yield link
        return
    yield name


def _read_whole(path: Path, kind: str, units: str | None, precision: list[float] | None = None) -> tuple[TopoDS_Shape, str]:
    """Read ``path`` with OCCT, check that it was read whole; (shape, unit read in). The precision the
    file states, in the unit read in, is appended to ``precision`` (when it states one)."""
    from OCP.IFSelect import IFSelect_RetDone

    with captured_messages() as printed:
        if kind == "STEP":
            from OCP.STEPControl import STEPControl_Reader

            reader = STEPControl_Reader()
        else:
            from OCP.IGESControl import IGESControl_Controller, IGESControl_Reader

            IGESControl_Controller.Init_s()
            reader = IGESControl_Reader()
        with _utf8_name(path) as readable:
            status = reader.ReadFile(readable)
        name = _namer(path, kind, reader)
        failures = _reader_failures(reader.WS().ModelCheckList(), name) if status == IFSelect_RetDone else []
        failures = [text for text in failures if not _about_looks(text)]
        if status == IFSelect_RetDone and not failures:
            if kind == "STEP" and (fault := _step_length_fault(reader)):
                raise ReadError(f"cannot read {path.name!r}: {fault}")
            unit = _use_unit(reader, kind, units, path.name)
            stated = _stated_precision(reader, kind) / MM_PER_UNIT[unit]
            if precision is not None and math.isfinite(stated) and stated > 0.0:
                precision.append(stated)
            curves = _step_curves(reader.StepModel()) if kind == "STEP" else _iges_curves(reader.IGESModel())
            nested = next((container for curve, container, _ in curves if curve is _NESTED), None)
            if nested is not None:
                raise ReadError(f"cannot read {path.name!r}: {name(nested)} contains itself (composite curves nested "
                                f"more than {_MAX_NESTING} deep)")  # fmt: skip
            roots = reader.NbRootsForTransfer()
            transferred = reader.TransferRoots()
            if transferred < roots:
                failures.append(f"only {transferred} of {roots} root entities could be transferred")
                failures += _culprits(kind, reader, curves, name)
    if status != IFSelect_RetDone or failures:
        reasons = failures or _printed_reasons(printed) or [status.name]
        more = f" (and {len(reasons) - 3} more)" if len(reasons) > 3 else ""
        raise ReadError(f"cannot read {path.name!r}: the {kind} reader reports: " + "; ".join(reasons[:3]) + more)
    shape = reader.OneShape()
    if shape.IsNull():
        raise ReadError(f"cannot read {path.name!r}: the {kind} reader found no transferable geometry")
    edges, finite = _edge_count(shape)
    if edges < len(curves) or not finite:
        raise ReadError(_dropped(path, kind, reader, curves, edges, finite))
    return shape, unit


# ------------------------------------------------------------------ units


def _use_unit(reader: Any, kind: str, units: str | None, name: str) -> str:
    """Make ``reader`` transfer in ``units``; None: in the file's own unit if spiral_cad names it
    (mm, cm, m, km, in, ft), else in millimetres. Returns the unit's name."""
    if units is None:
        factor = _step_unit(reader) if kind == "STEP" else _iges_unit(reader)
        if not (math.isfinite(factor) and factor > 0.0):
            raise ReadError(f"cannot read {name!r}: the file declares a length unit of {factor!r} mm")
        units = next((unit for unit, size in MM_PER_UNIT.items() if size == factor), "mm")
    if kind == "STEP":
        reader.SetSystemLengthUnit(MM_PER_UNIT[units])
    else:
        model = reader.IGESModel()
        section = model.GlobalSection()
        section.SetCascadeUnit(MM_PER_UNIT[units])
        model.SetGlobalSection(section)
    return units


def _step_unit(reader: Any) -> float:
    """Millimetres per length unit of the first unit context of a STEP file (1 if it has none)."""
    from OCP.STEPConstruct import STEPConstruct_UnitContext
    from OCP.StepData import StepData_Factors
    from OCP.StepRepr import StepRepr_GlobalUnitAssignedContext, StepRepr_RepresentationContext

    for entity in _entities_of(reader.StepModel(), StepRepr_RepresentationContext):
        if not isinstance(entity, StepRepr_GlobalUnitAssignedContext):
            entity = getattr(entity, "GlobalUnitAssignedContext", lambda: None)()
        if entity is not None:
            context = STEPConstruct_UnitContext()
            context.ComputeFactors(entity, StepData_Factors())
            if context.LengthDone():
                return context.LengthFactor()
    return 1.0


def _step_length_fault(reader: Any) -> str:
    """Why the global units of a STEP file give no length (its unit of length is a second, say), or ``""``:
    a context that assigns units must assign a length unit among them."""
    from OCP.StepRepr import StepRepr_GlobalUnitAssignedContext, StepRepr_RepresentationContext

    for entity in _entities_of(reader.StepModel(), StepRepr_RepresentationContext):
        if not isinstance(entity, StepRepr_GlobalUnitAssignedContext):
            entity = getattr(entity, "GlobalUnitAssignedContext", lambda: None)()
        if entity is None or not entity.NbUnits():
            continue
        units = [entity.UnitsValue(k) for k in range(1, entity.NbUnits() + 1)]
        if any(unit is not None and "LengthUnit" in type(unit).__name__ for unit in units):
            return ""
        return "its units give no length: " + ", ".join(_unit_name(unit) for unit in units) + " (a length unit is required)"
    return ""


def _unit_name(unit: Any) -> str:
    """``second (time unit)`` for a STEP named unit (SI or conversion based)."""
    if unit is None:
        return "a missing unit"
    kind = re.sub(r"(?<!^)(?=[A-Z])", " ", type(unit).__name__.split("And")[-1]).lower()  # "SiUnitAndTimeUnit" → "time unit"
    try:
        name = unit.Name()
    except Exception:  # noqa: BLE001 - a unit without a name
        return kind
    text = name.ToCString() if hasattr(name, "ToCString") else getattr(name, "name", str(name))
    return f"{re.sub(r'^StepBasic_sun', '', str(text)).lower()} ({kind})"


def _stated_precision(reader: Any, kind: str) -> float:
    """The precision the file states, in mm (0.0: none): the first length ``UNCERTAINTY_MEASURE_WITH_UNIT``
    of a STEP file's representation contexts (in its length unit), an IGES file's minimum resolution."""
    if kind != "STEP":
        return float(reader.IGESModel().GlobalSection().Resolution()) * _iges_unit(reader)
    from OCP.STEPConstruct import STEPConstruct_UnitContext
    from OCP.StepRepr import StepRepr_GlobalUncertaintyAssignedContext, StepRepr_RepresentationContext

    for entity in _entities_of(reader.StepModel(), StepRepr_RepresentationContext):
        if not isinstance(entity, StepRepr_GlobalUncertaintyAssignedContext):
            entity = getattr(entity, "GlobalUncertaintyAssignedContext", lambda: None)()
        if entity is not None:
            context = STEPConstruct_UnitContext()
            if context.ComputeTolerance(entity) == 0 and context.HasUncertainty():
                return float(context.Uncertainty()) * _step_unit(reader)
    return 0.0


def _iges_unit(reader: Any) -> float:
    """Millimetres per unit of an IGES file (global section: unit flag, or unit name for flag 3)."""
    return reader.IGESModel().GlobalSection().UnitValue()


# ------------------------------------------------------- curve accounting


def _leaves(curve: Any, container: Any, position: int, parts: Callable[[Any], list | None], found: list, depth: int = 0) -> None:
    """Append ``(curve, container, position)``, or for a composite curve (``parts(curve)``: its
    ``(position, member)`` pairs, None for a curve that is not composite) those of its leaves.

    A member that is missing is listed as None (it is certainly dropped); a
    composite nested deeper than ``_MAX_NESTING`` as ``_NESTED``.
    """
    members = parts(curve)
    if members is None:
        found.append((curve, container, position))
    elif depth > _MAX_NESTING:
        found.append((_NESTED, curve, 0))
    else:
        for k, member in members:
            if member is None:
                found.append((None, curve, k))
            else:
                _leaves(member, curve, k, parts, found, depth + 1)


def _step_curves(model: Any) -> list[tuple[Any, Any, int]]:
    """``(curve, container, position)`` of every curve the STEP reader must turn into an edge:
    every ``EDGE_CURVE`` (its geometry; its container the first ``CONNECTED_EDGE_SET`` that lists
    it, else the edge itself), every leaf segment of a composite curve in a geometric set, every
    other curve of a geometric set (each listed curve once, as OCCT transfers it)."""
    from OCP.StepGeom import StepGeom_CompositeCurve, StepGeom_Curve
    from OCP.StepShape import StepShape_ConnectedEdgeSet, StepShape_EdgeCurve, StepShape_GeometricSet

    def parts(curve: Any) -> list | None:
        if not isinstance(curve, StepGeom_CompositeCurve):
            return None
        segments = (curve.SegmentsValue(k) for k in range(1, curve.NbSegments() + 1))
        return [(k, s.ParentCurve() if s is not None else None) for k, s in enumerate(segments, 1)]

    found: list[tuple[Any, Any, int]] = []
    listed: dict[int, Any] = {}  # a curve listed in two sets is transferred once (kept alive: ids stay unique)
    places: dict[int, tuple[Any, Any, int]] = {}  # id(edge) → (edge kept alive: ids stay unique, its set, position)
    for edge_set in _entities_of(model, StepShape_ConnectedEdgeSet):
        edges = edge_set.CesEdges()
        for k in range(1, (edges.Length() if edges is not None else 0) + 1):
            edge = edges.Value(k)
            places.setdefault(id(edge), (edge, edge_set, k))
    for entity in _entities_of(model, StepShape_EdgeCurve):
        _, container, k = places.get(id(entity), (entity, entity, 0))
        found.append((entity.EdgeGeometry(), container, k))
    for entity in _entities_of(model, StepShape_GeometricSet):
        for k in range(1, entity.NbElements() + 1):
            curve = entity.ElementsValue(k).Curve()
            if isinstance(curve, StepGeom_Curve) and id(curve) not in listed:
                listed[id(curve)] = curve
                _leaves(curve, entity, k, parts, found)
    return found


def _entities_of(model: Any, kind: Any) -> list[Any]:
    """The entities of ``model`` of class ``kind`` (or derived), in file order; OCCT filters them
    (a Python loop over a 70 000-entity file costs 0.1 s)."""
    selected = model.Entities()
    selected.SelectType(kind.get_type_descriptor_s(), True)
    found = []
    selected.Start()
    while selected.More():
        found.append(selected.Value())
        selected.Next()
    return found


def _iges_curves(model: Any) -> list[tuple[Any, Any, int]]:
    """``(curve, container, position)`` of every leaf of every independent IGES curve entity.

    A composite curve (102) counts its members (recursively; points and
    other non-curves among them are skipped); an entity that is a member of a
    composite is not counted again on its own.
    """
    entities = [model.Entity(i) for i in range(1, model.NbEntities() + 1)]

    def is_curve(entity: Any) -> bool:
        kind = entity.TypeNumber()
        return kind in _IGES_CURVES and (kind != 106 or entity.FormNumber() in _IGES_POLYLINE_FORMS)

    def parts(curve: Any) -> list | None:
        if curve.TypeNumber() != 102:
            return None
        members = ((k, curve.Curve(k)) for k in range(1, curve.NbCurves() + 1))
        return [(k, m) for k, m in members if m is None or is_curve(m)]

    members = {model.DNum(m) for e in entities if e.TypeNumber() == 102 for _, m in cast(list, parts(e)) if m is not None}
    found: list[tuple[Any, Any, int]] = []
    for entity in entities:
        if is_curve(entity) and entity.SubordinateStatus() % 2 == 0 and model.DNum(entity) not in members:
            _leaves(entity, None, 0, parts, found)
    return found


def _edge_count(shape: TopoDS_Shape) -> tuple[int, bool]:
    """Distinct edges of ``shape`` that are not degenerated (a surface's pole), and whether each
    spans a finite parameter range (NaN where OCCT could not place a vertex on a non-finite curve)."""
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    count, finite = 0, True
    for i in range(1, edges.Extent() + 1):
        edge = TopoDS.Edge_s(edges.FindKey(i))
        if not BRep_Tool.Degenerated_s(edge):
            count += 1
            first, last = BRep_Tool.Range_s(edge)
            finite = finite and math.isfinite(first) and math.isfinite(last)
    return count, finite


def _dropped(path: Path, kind: str, reader: Any, curves: list[tuple[Any, Any, int]], edges: int, finite: bool) -> str:
    """The message for a transfer that made fewer edges than the file has curves, or an edge
    that is not finite: which curves, and why."""
    head = f"cannot read {path.name!r}: the {kind} reader made {edges} edges of the file's {len(curves)} curves"
    name = _namer(path, kind, reader)
    named = _culprits(kind, reader, curves, name)
    if not named:
        named = _reader_failures(reader.WS().TransferReader().LastCheckList(), name) or ["which one is not known"]
    more = f" (and {len(named) - 3} more)" if len(named) > 3 else ""
    return f"{head}{'' if finite else ', not all of them finite'}; not read: " + "; ".join(named[:3]) + more


def _culprits(kind: str, reader: Any, curves: list[tuple[Any, Any, int]], name: Callable[[Any], str]) -> list[str]:
    """Each curve that cannot become an edge on its own, named with its place and the reason."""
    if kind == "STEP":
        faults = [(curve, container, k, _step_curve_fault(curve)) for curve, container, k in curves]
    else:
        faults = [(curve, container, k, _iges_curve_fault(reader.IGESModel(), curve)) for curve, container, k in curves]
    return [
        f"{name(curve) if curve is not None else 'a missing curve'}"
        + (f" ({_part_word(kind, container)} {k} of {name(container)})" if k and container is not None else "")
        + f": {fault}"
        for curve, container, k, fault in faults
        if fault
    ]


def _part_word(kind: str, container: Any) -> str:
    """What a numbered part of ``container`` is called: an edge of an edge set, a segment, an IGES member."""
    if kind != "STEP":
        return "member"
    return "edge" if _class_name(container) == "ConnectedEdgeSet" else "segment"


def _finite_fault(curve: Any) -> str:
    """Why an OCCT curve cannot be an edge (a non-finite pole or point), or ``""``."""
    values = []
    if hasattr(curve, "NbPoles"):
        values += [c for i in range(1, curve.NbPoles() + 1) for c in curve.Pole(i).Coord()]
    first, last = curve.FirstParameter(), curve.LastParameter()
    for u in (first, last, 0.5 * (first + last)):
        if math.isfinite(u):
            values += curve.Value(u).Coord()
    return "" if all(math.isfinite(v) for v in values) else "a point or control point is not finite"


def _step_curve_fault(curve: Any) -> str:
    """Why the STEP curve entity cannot become an edge on its own, or ``""``."""
    from OCP.StepData import StepData_Factors
    from OCP.StepToGeom import StepToGeom

    if curve is None:
        return "the segment names no curve"
    try:
        made = StepToGeom.MakeCurve_s(curve, StepData_Factors())
    except Exception as error:  # OCCT's Standard_Failure: the curve is malformed
        return f"OCCT cannot translate it ({type(error).__name__})"
    return "OCCT cannot translate it" if made is None else _finite_fault(made)


def _iges_curve_fault(model: Any, curve: Any) -> str:
    """Why the IGES curve entity cannot become an edge on its own, or ``""``."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.IGESToBRep import IGESToBRep_CurveAndSurface

    if curve is None:
        return "the composite names no curve there"
    translator = IGESToBRep_CurveAndSurface()
    translator.SetModel(model)
    try:
        made = translator.TransferCurveAndSurface(curve)
    except Exception as error:
        return f"OCCT cannot translate it ({type(error).__name__})"
    if made.IsNull():
        return "OCCT cannot translate it"
    edges = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(made, TopAbs_EDGE, edges)
    for i in range(1, edges.Extent() + 1):
        adaptor = BRepAdaptor_Curve(TopoDS.Edge_s(edges.FindKey(i)))
        u0, u1 = adaptor.FirstParameter(), adaptor.LastParameter()
        if not all(math.isfinite(c) for u in (u0, u1, 0.5 * (u0 + u1)) for c in adaptor.Value(u).Coord()):
            return "a point or control point is not finite"
    return ""


def _namer(path: Path, kind: str, reader: Any) -> Callable[[Any], str]:
    """A function naming the file's entities for messages; it looks them up on its first use only."""
    named: list[Callable[[Any], str]] = []

    def name(entity: Any) -> str:
        if not named:
            named.append(_step_namer(path, reader.StepModel()) if kind == "STEP" else _iges_namer(reader.IGESModel()))
        return named[0](entity)

    return name


def _step_namer(path: Path, model: Any) -> Callable[[Any], str]:
    """Names STEP entities as the file does (``#23 B_SPLINE_CURVE_WITH_KNOTS``).

    OCCT numbers entities in file order; their ``#`` labels are read from the
    file's DATA section (strings and comments skipped). If the two do not
    agree, entities are named by their position and type.
    """
    alive = [model.Value(i) for i in range(1, model.NbEntities() + 1)]  # keeps each wrapper, so ``is`` finds it
    rank = {id(entity): i for i, entity in enumerate(alive)}
    labels = _step_labels(path)
    if len(labels) != len(alive):
        labels = [f"entity {i + 1} ({_class_name(entity)})" for i, entity in enumerate(alive)]

    def name(entity: Any) -> str:
        i = rank.get(id(entity))
        return labels[i] if i is not None else _class_name(entity)

    return name


def _class_name(entity: Any) -> str:
    return type(entity).__name__.split("_", 1)[-1]


#: the words of an entity that only says how a part looks (a style, colour, font, marker, layer or annotation)
_LOOKS = {"STYLE", "COLOUR", "COLOR", "DRAUGHTING", "FONT", "MARKER", "RENDERING", "FILL", "INVISIBILITY",
          "ANNOTATION", "LAYER"}  # fmt: skip
#: a complaint's entity ("#1159 SURFACE_STYLE_RENDERING_WITH_PROPERTIES: …", "CurveStyle: …") and the parameter
#: it names ("Parameter n0.2 (curve_font) …", an attribute of a style another entity refers to)
_COMPLAINT = re.compile(r"(?:#\d+\s+)?(\w+)\s*:(?:.*?\(([a-z_.]+)\))?")


def _about_looks(text: str) -> bool:
    """A reader's complaint only about how a part looks, with which no geometry is lost (Inventor 2021 leaves
    a rendering method unset; other writers a curve font or marker OCCT does not take)."""
    found = _COMPLAINT.match(text)
    if not found:
        return False
    words = set(re.sub(r"(?<=[a-z])(?=[A-Z])", "_", found.group(1)).upper().split("_"))
    named = set(re.split(r"[_.]", (found.group(2) or "").upper()))
    return bool(words & _LOOKS) or bool(named & _LOOKS)


_STEP_TOKEN = re.compile(rb"'(?:[^']|'')*'|/\*.*?\*/|#(\d+)\s*=\s*([A-Za-z0-9_]*)", re.S)


def _step_labels(path: Path) -> list[str]:
    """``"#N TYPE"`` of every entity instance of a STEP file, in file order (``TYPE`` empty: a complex instance)."""
    data = path.read_bytes()
    start = data.find(b"DATA;")
    labels = []
    for match in _STEP_TOKEN.finditer(data, start if start >= 0 else 0):
        if match.group(1) is not None:
            kind = match.group(2).decode("ascii").upper()
            labels.append(f"#{int(match.group(1))} {kind}" if kind else f"#{int(match.group(1))} (complex entity)")
    return labels


def _iges_namer(model: Any) -> Callable[[Any], str]:
    """Names IGES entities by type and directory entry: ``entity 126 (D3)``."""

    def name(entity: Any) -> str:
        return f"entity {entity.TypeNumber()} (D{model.DNum(entity)})"

    return name


# ------------------------------------------------------- reader's verdict


def _check_iges_sections(path: Path) -> None:
    """Refuse an IGES file whose sections disagree with its terminate record (cut short or damaged).

    Every IGES record carries its section letter in column 73 (S, G, D, P,
    T); the single T record at the end counts the S, G, D and P records.
    """
    counts = {"S": 0, "G": 0, "D": 0, "P": 0, "T": 0}
    last = ""
    with open(path, "rb") as handle:
        for raw in handle:
            record = raw.rstrip(b"\r\n")
            letter = chr(record[72]) if len(record) >= 73 else "?"
            if letter in counts:
                counts[letter] += 1
                last = record.decode("ascii", "replace") if letter == "T" else last
    if counts["T"] != 1:
        raise ReadError(f"cannot read {path.name!r}: no IGES terminate section (the file is cut short or not IGES)")
    declared = {}
    for key, start in (("S", 0), ("G", 8), ("D", 16), ("P", 24)):
        field = last[start : start + 8]
        try:
            declared[key] = int(field[1:])
        except ValueError:
            raise ReadError(f"cannot read {path.name!r}: damaged IGES terminate record {last[:32]!r}") from None
    found = {key: counts[key] for key in declared}
    if found != declared:
        raise ReadError(
            f"cannot read {path.name!r}: the IGES terminate record declares {declared} records per section, "
            f"the file holds {found} (cut short or damaged)"
        )


def _reader_failures(checks: Any, name: Callable[[Any], str] | None = None) -> list[str]:
    """The failure messages of an OCCT check list (and a missing end of file), de-duplicated, in
    order; each after the entity it concerns when ``name`` names entities."""
    found: list[str] = []
    checks.Start()
    while checks.More():
        check = checks.Value()
        texts = [check.CFail(i) for i in range(1, check.NbFails() + 1)]
        texts += [w for w in (check.CWarning(i) for i in range(1, check.NbWarnings() + 1)) if "Terminate Section" in w]
        entity = check.Entity() if name is not None else None
        for text in texts:
            text = f"{name(entity)}: {text.strip()}" if name is not None and entity is not None else text.strip()
            if text and text not in found:
                found.append(text)
        checks.Next()
    return found


def _printed_reasons(printed: list[str]) -> list[str]:
    """Error lines the reader printed (its only report of a syntax error)."""
    lines = [line.strip(" *") for line in printed if "ERR" in line or "rror" in line]
    return [line for line in lines if line]
