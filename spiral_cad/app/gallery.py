"""The gallery of G2 parts a machinist draws: a bracket, a plate with holes and a pocket, a boss on a
base and a stepped block, each rounded by ``g2_fillet`` on every edge.

``spiral-cad demo`` writes their STEP files (``gallery_NAME.step``), and the solids tutorial's zebra pictures
show each beside build123d's circular ``fillet`` of the same edges.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from build123d import Part

__all__ = ["GALLERY", "gallery_part", "write_gallery"]


def _bracket() -> Part:
    from build123d import Box, Cylinder, Pos

    foot = Box(60, 20, 12) + Pos(-20, 24, 0) * Box(20, 28, 12)  # an L in plan, one concave corner
    return foot - [Pos(x, y, 0) * Cylinder(3, 12) for x, y in ((18, 0), (-20, 26))]


def _plate() -> Part:
    from build123d import Box, Cylinder, Pos

    plate = Box(64, 40, 12) - Pos(0, 0, 3) * Box(28, 16, 6)
    return plate - [Pos(x, y, 0) * Cylinder(3.5, 12) for x in (-23, 23) for y in (-11, 11)]


def _boss() -> Part:
    from build123d import Box, Cylinder, Pos

    return Box(50, 36, 8) + Pos(5, 0, 9) * Cylinder(9, 10) - Pos(5, 0, 5) * Cylinder(2.5, 18)  # through the boss and the base


def _steps() -> Part:
    from build123d import Box, Pos

    return Box(44, 34, 8) + Pos(0, 0, 8) * Box(30, 22, 8) + Pos(0, 0, 16) * Box(16, 10, 8)


#: Each gallery part: its sharp build123d part and the radius every edge is rounded with.
GALLERY: dict[str, tuple[Callable[[], Part], float]] = {
    "bracket": (_bracket, 2.5),
    "plate_pocket_holes": (_plate, 2.0),
    "boss_on_base": (_boss, 2.5),
    "stepped_block": (_steps, 2.0),
}


def gallery_part(name: str, *, g2: bool = True) -> Part:
    """The gallery part ``name`` with every edge rounded: G2 by ``g2_fillet`` (else build123d's circular
    ``fillet`` of the same edges and radius, for comparison).

    Raises:
        ValueError: an unknown name.
    """
    if name not in GALLERY:
        raise ValueError(f"name must be one of {', '.join(GALLERY)}; got {name!r:.40}")
    from build123d import Part, Solid, fillet

    from ..cad.stack_fillet import fillet_part_edges

    make, radius = GALLERY[name]
    sharp = make()
    if not g2:
        return fillet(sharp.edges(), radius)
    slab = fillet_part_edges(sharp.solids()[0].wrapped, [e.wrapped for e in sharp.edges()], radius)
    return Part(Solid(slab.shape).wrapped)


def write_gallery(folder: Path) -> list[Path]:
    """Write each gallery part, rounded G2, as ``folder/gallery_NAME.step`` (mm); the paths written."""
    from ..cad.export import export_step

    written = []
    for name in GALLERY:
        path = folder / f"gallery_{name}.step"
        export_step(gallery_part(name), path)
        written.append(path)
    return written
