"""Files from chains: STEP, IGES, DXF, SVG (and OpenDRIVE for alignments), and samples for machines.

Every writer takes the chain's own length unit and declares it the way its
readers expect, and takes a ``name`` (default: the file name's stem) that
becomes the STEP product, the IGES product id and entity name, the DXF
layer and the SVG id and title. A name is 1 to 255 characters of printable
text (no control characters); each format escapes or replaces what it cannot
hold (``spiral_cad.io.names``). The originating system is
``spiral_cad <version>``. How each format stores a spiral:

=======  ==========================================================  ==================================
format   spiral stored as                                             unit declared by
=======  ==========================================================  ==================================
STEP     B_SPLINE_CURVE_WITH_KNOTS, degree 3, 4 poles, Bézier knots   SI_UNIT (+ prefix) / CONVERSION_BASED_UNIT
IGES     entity 126 (rational B-spline, degree 3, 4 poles, weights 1)  global section unit flag and name
DXF      SPLINE, degree 3, 4 control points, knots 0 0 0 0 1 1 1 1    $INSUNITS and $MEASUREMENT
SVG      one cubic ``C`` command (the Bézier itself)                  width/height in mm or in; viewBox
=======  ==========================================================  ==================================

Each is exactly the same cubic; see README for what each round trip keeps.
Chains in space go to STEP, IGES and DXF in 3-D (exact lines, circles about
their normal and Bézier spirals with their four poles); SVG is a plane
format. ``export_samples`` writes a path as points for a robot or CNC
post-processor (``spiral_cad.io.samples``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..core.chain import Chain
from ..core.units import DEFAULT_UNITS, length_unit, shared_unit
from ..io.names import MAX_TEXT_LENGTH, check_name
from ..io.opendrive import CrossSection

PathLike = str | os.PathLike

__all__ = [
    "CrossSection",
    "export_dxf",
    "export_iges",
    "export_opendrive",
    "export_samples",
    "export_step",
    "export_svg",
    "originating_system",
]


def originating_system() -> str:
    """``spiral_cad <version>``: the originating system written into every file."""
    from .._version import __version__

    return f"spiral_cad {__version__}"


def _chains(obj: Any) -> list[Chain] | None:
    """``obj`` as a list of chains, or None when it holds something else."""
    if isinstance(obj, Chain):
        return [obj]
    if isinstance(obj, Iterable) and not isinstance(obj, (str, bytes, os.PathLike)):
        items = list(obj)
        if items and all(isinstance(c, Chain) for c in items):
            return items
    return None


def _require_chains(obj: Any) -> list[Chain]:
    chains = _chains(obj)
    if chains is None:
        raise ValueError(f"expected a Chain or a non-empty list of Chains; got {type(obj).__name__}")
    return chains


def _name(name: str | None, path: PathLike) -> str:
    if name is None:
        return check_name(Path(path).stem, "name (the file name's stem, used when no name is given)")
    return check_name(name)


def _units(chains: list[Chain] | None, units: str | None) -> str:
    """The file's unit: the chains' own (they must agree, and ``units`` may only confirm it), else ``units`` or mm."""
    if chains is None:
        return DEFAULT_UNITS if units is None else length_unit(units)
    return shared_unit((c.units for c in chains), units)


def export_step(obj: Any, path: PathLike, *, name: str | None = None, units: str | None = None) -> None:
    """Write STEP (AP214).

    Chains are written directly (``spiral_cad.io.step``): one connected
    wire per chain, exact lines, circles and Bézier spirals, in the chain's
    unit. Any other shape (build123d, CadQuery, OCP) is declared in ``units``
    (default mm, build123d's convention; give the design's unit, e.g.
    ``units="m"`` for a road) and written as ONE product: its solids, shells
    and faces through OCCT's writer (17 significant digits), its wires as
    connected edge sets of their exact B-splines, in wire order
    (``spiral_cad.cad.step_occ``), so FreeCAD and OCCT read one part
    with real wires. A G2 solid (``ContinuousBox``, ``g2_slab``, ``g2_fillet``
    of edges) has the deviation of its approximated surfaces written into the
    header's FILE_DESCRIPTION; so has a part built of them (``BuildPart``, a
    move, a boolean that keeps their surfaces: ``roll_surfaces.recorded_approximation``
    recognises their faces; not a scaled copy).

    Args:
        obj: a Chain, a list of Chains, or a build123d/CadQuery/OCP shape.
        path: the file to write.
        name: product name (default: the file name's stem).
        units: for shapes, their length unit; for chains only a check.

    Raises:
        ValueError: an unsupported object, unknown or contradicting units, a
            name that is not 1–255 characters of printable text.
        OSError: the file could not be written.
    """
    chains = _chains(obj)
    label, unit = _name(name, path), _units(chains, units)
    if chains is not None:
        from ..io.step import write_step

        write_step(chains, path, label, unit, originating_system())
    else:
        from .occ import as_occ_shape
        from .roll_surfaces import recorded_approximation
        from .slabs import approximation_note
        from .step_occ import write_shape_step

        approximation = getattr(obj, "approximation", None)  # G2 solids say how far any surface is from exact
        if approximation is None:  # a part built of them (BuildPart, booleans) carries their faces
            approximation = recorded_approximation(as_occ_shape(obj))
        note = None if approximation is None else approximation_note(float(approximation), unit)
        write_shape_step(obj, path, label, unit, originating_system(), note)


def export_iges(obj: Any, path: PathLike, *, name: str | None = None, units: str | None = None) -> None:
    """Write IGES 5.3 in BRep mode through OCCT (lines 110, circles 100, spirals exact 126); needs OCP.

    Args and errors as :func:`export_step`.
    """
    from .iges import write_iges

    chains = _chains(obj)
    write_iges(obj, path, _name(name, path), _units(chains, units), originating_system())


def export_dxf(obj: Chain | Iterable[Chain], path: PathLike, *, name: str | None = None) -> None:
    """Write chains as DXF R2010 (LINE, ARC, exact SPLINE) on layer ``name``, in the chains' unit; needs ezdxf."""
    from ..io.dxf import write_dxf

    chains = _require_chains(obj)
    write_dxf(chains, path, _name(name, path), _units(chains, None))


def export_svg(obj: Chain | Iterable[Chain], path: PathLike, *, name: str | None = None, margin: float = 0.05) -> None:
    """Write chains as SVG at true size (one path per chain; ``margin`` a fraction of the drawing's size)."""
    from ..io.svg import write_svg

    chains = _require_chains(obj)
    if any(c.dim == 3 for c in chains):
        raise ValueError("SVG is a plane format; this chain is in space (write STEP, IGES or DXF, which hold 3-D paths)")
    write_svg(chains, path, _name(name, path), _units(chains, None), margin)


def export_samples(chain: Chain, path: PathLike, *, step: float | None = None, chord_tolerance: float | None = None) -> int:
    """Write a path's samples as CSV for a robot or CNC post-processor: s, x, y, z, unit tangent and curvature
    at most ``step`` apart, or close enough that the path strays at most ``chord_tolerance`` from the chord
    between neighbours (measured), every segment's ends included; the unit in every header.

    Returns:
        The number of samples written.

    Raises:
        ValueError: not a Chain, neither or both of step and chord_tolerance, or too many samples.
        OSError: the file could not be written.
    """
    from ..io.samples import write_samples

    return write_samples(chain, path, step=step, chord_tolerance=chord_tolerance)


def export_opendrive(
    obj: Any,
    path: PathLike,
    *,
    name: str | None = None,
    cross_section: CrossSection = CrossSection(),
    geo_reference: str | None = None,
    profile: Any = None,
    superelevation: Any = None,
) -> None:
    """Write ASAM OpenDRIVE 1.8: one road per alignment or chain, spirals as exact ``paramPoly3``.

    An ``Alignment`` brings its start station (as ``userData``) and, when it
    was designed with criteria, the superelevation of every curve (a
    ``lateralProfile`` of exact cubics, C1: ``spiral_cad.design.Superelevation``).
    A ``Profile`` gives the ``elevationProfile`` (its parabolas and grades
    exactly); without one the road is level at 0. See
    ``spiral_cad.io.opendrive`` for the mapping; lengths are converted
    to metres, OpenDRIVE's unit.

    Args:
        obj: an ``Alignment``, a ``Chain``, or a list of them.
        path: the .xodr file to write.
        name: the header's and each road's name (default: the file name's stem).
        cross_section: the lanes of every road (default: one 3.5 m driving
            lane each way and 2.5 m shoulders).
        geo_reference: a PROJ string (or WKT, up to 10 000 characters of
            printable text, newlines allowed) for the header's ``geoReference``.
        profile: the ``Profile`` of an alignment, or one per item (None for
            none); it must cover its alignment.
        superelevation: a ``Superelevation`` (or one per item) instead of the
            one the alignment's criteria give.

    Raises:
        ValueError: an unsupported object, chains of different units, a
            name or ``geo_reference`` that is not printable text, or a
            profile or superelevation that does not fit its alignment.
    """
    from ..design.alignment import Alignment
    from ..design.centerline import check_profile
    from ..design.superelevation import Superelevation
    from ..io.opendrive import RoadToWrite, write_opendrive

    items = list(obj) if isinstance(obj, (list, tuple)) else [obj]
    if not items or not all(isinstance(i, (Alignment, Chain)) for i in items):
        raise ValueError(f"expected an Alignment, a Chain or a list of them; got {type(obj).__name__}")
    label = _name(name, path)
    if geo_reference is not None:
        check_name(geo_reference, "geo_reference", limit=MAX_TEXT_LENGTH, multiline=True)
    profiles = _per_item(profile, len(items), "profile")
    bankings = _per_item(superelevation, len(items), "superelevation")
    roads = []
    for k, (item, its_profile, banking) in enumerate(zip(items, profiles, bankings)):
        road_name = label if len(items) == 1 else f"{label}-{k + 1}"
        if isinstance(item, Chain):
            if its_profile is not None or banking is not None:
                raise ValueError(f"item {k}: a profile or superelevation needs an Alignment (its stations), not a Chain")
            roads.append(RoadToWrite(item, road_name))
            continue
        elevation = None
        if its_profile is not None:
            check_profile(item, its_profile)
            elevation = its_profile.records(item.start_station, item.end_station)
        if banking is None:
            banking = Superelevation.from_alignment(item)
        elif not isinstance(banking, Superelevation):
            raise ValueError(f"superelevation must be a Superelevation; got {type(banking).__name__}")
        roads.append(RoadToWrite(item.chain, road_name, item.start_station, elevation, banking.records()))
    units = _units([r.chain for r in roads], None)
    write_opendrive(roads, path, label, units, originating_system(), cross_section, geo_reference)


def _per_item(value: Any, count: int, name: str) -> list:
    """One value per exported item: None, one object for a single item, or a list of ``count``."""
    if isinstance(value, (list, tuple)):
        if len(value) != count:
            raise ValueError(f"{name} needs one entry per item ({count}); got {len(value)}")
        return list(value)
    if value is not None and count != 1:
        raise ValueError(f"{name}: give a list with one entry per item ({count})")
    return [value] * count
