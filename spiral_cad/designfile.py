"""JSON design files: validation, building and writing every output.

A design file holds ``units`` and a list of ``designs``; each design has a
``name``, a ``type`` and the fields of that type (see ``FORMAT``). Every
field is checked before anything is built, and every design is built before
anything is written, so a bad file writes nothing.
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .core.chain import Chain
from .core.errors import NoSolutionError

FORMAT = """\
{
  "units": "m",                          one of m, mm, cm, km, in, ft (labels and CSV)
  "designs": [
    {"name": "highway", "type": "alignment",
     "pis": [[x, y], ...],               ≥ 3 points of intersection, in travel order
     "radii": [r, ...],                  one positive radius per interior PI (or one number)
     "spiral_angles_deg": [θ | [θin, θout], ...]   or "spiral_lengths": [L | [Lin, Lout], ...]
     "start_station": 0},                optional chainage of the first PI
    {"name": "oval", "type": "circle_chain",
     "circles": [{"center": [x, y], "radius": r}, ...]},   signed radius = travel sense (+ ccw)
    {"name": "robot", "type": "rounded_polyline",
     "points": [[x, y], ...],
     "max_curvature": k  | "curvature": k  | neither (as large as fits),
     "method": "walton-meek" | "g2cbs"},
    {"name": "t", "type": "transition", "case": "line_to_circle" | "circle_to_circle" |
     "line_to_line" | "circle_in_circle", ...that function's arguments by name...}
  ]
}"""

UNITS = ("m", "mm", "cm", "km", "in", "ft")
TRANSITION_ARGS = {
    "line_to_circle": ("point", "direction", "center", "radius"),
    "circle_to_circle": ("center0", "radius0", "center1", "radius1"),
    "line_to_line": ("p0", "corner", "p1", "curvature"),
    "circle_in_circle": ("center0", "radius0", "center1", "radius1"),
}
OPTIONAL = {"curvature"}


class DesignError(ValueError):
    """A design file is malformed or infeasible; the message names the field and value."""


@dataclass
class Built:
    """One built design: its chain and the object that made it (for tables)."""

    name: str
    kind: str
    chain: Chain
    source: Any = None
    notes: dict[str, Any] = field(default_factory=dict)


# ------------------------------------------------------------ validation


def _number(value: Any, where: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignError(f"{where}: must be a finite number; got {value!r}")
    if positive and not value > 0:
        raise DesignError(f"{where}: must be positive; got {value!r}")
    return float(value)


def _point(value: Any, where: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise DesignError(f"{where}: must be a point [x, y]; got {value!r}")
    return _number(value[0], f"{where}[0]"), _number(value[1], f"{where}[1]")


def _points(value: Any, where: str, minimum: int) -> list[tuple[float, float]]:
    if not isinstance(value, list) or len(value) < minimum:
        raise DesignError(f"{where}: must be a list of at least {minimum} points [x, y]; got {value!r}")
    return [_point(p, f"{where}[{i}]") for i, p in enumerate(value)]


def _pairs(value: Any, where: str, count: int, convert: Callable[[Any, str], float]) -> list[tuple[float, float]]:
    """One number for all, or a list of numbers / [in, out] pairs, one per interior PI."""
    if not isinstance(value, list):
        v = convert(value, where)
        return [(v, v)] * count
    if len(value) != count:
        raise DesignError(f"{where}: needs one entry per interior PI ({count}); got {len(value)}")
    out = []
    for i, item in enumerate(value):
        if isinstance(item, list):
            if len(item) != 2:
                raise DesignError(f"{where}[{i}]: must be a number or [in, out]; got {item!r}")
            out.append((convert(item[0], f"{where}[{i}][0]"), convert(item[1], f"{where}[{i}][1]")))
        else:
            v = convert(item, f"{where}[{i}]")
            out.append((v, v))
    return out


def _degrees(value: Any, where: str) -> float:
    v = _number(value, where)
    if not 0 < v < 90:
        raise DesignError(f"{where}: spiral angles are in degrees and must lie in (0, 90); got {value!r}")
    return math.radians(v)


def _fields(design: dict, where: str, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> None:
    missing = [k for k in required if k not in design]
    if missing:
        raise DesignError(f"{where}: missing field(s) {', '.join(missing)}")
    unknown = sorted(set(design) - set(required) - set(optional) - {"name", "type"})
    if unknown:
        raise DesignError(f"{where}: unknown field(s) {', '.join(unknown)}")


def load(source: str | Path | dict) -> tuple[str, list[dict]]:
    """Parse and check the top level of a design (a JSON file path or a dict): (units, designs)."""
    if isinstance(source, dict):
        data = source
    else:
        try:
            text = Path(source).read_text(encoding="utf-8")
        except OSError as e:
            raise DesignError(f"cannot read design file {source}: {e.strerror}") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise DesignError(f"{source}: malformed JSON at line {e.lineno}, column {e.colno}: {e.msg}") from None
    if not isinstance(data, dict):
        raise DesignError(f"the design must be a JSON object with 'units' and 'designs'; got {type(data).__name__}")
    units = data.get("units", "m")
    if units not in UNITS:
        raise DesignError(f"units: must be one of {', '.join(UNITS)}; got {units!r}")
    designs = data.get("designs")
    if not isinstance(designs, list) or not designs:
        raise DesignError("designs: must be a non-empty list of designs")
    names = set()
    for i, d in enumerate(designs):
        if not isinstance(d, dict):
            raise DesignError(f"designs[{i}]: must be an object; got {d!r}")
        name = d.get("name")
        if not isinstance(name, str) or not name or not all(c.isalnum() or c in "-_" for c in name):
            raise DesignError(f"designs[{i}].name: must be a non-empty name of letters, digits, - and _; got {name!r}")
        if name in names:
            raise DesignError(f"designs[{i}].name: {name!r} is used twice")
        names.add(name)
        if d.get("type") not in BUILDERS:
            raise DesignError(f"designs[{i}].type: must be one of {', '.join(BUILDERS)}; got {d.get('type')!r}")
    return units, designs


# ------------------------------------------------------------- building


def _alignment(d: dict, where: str) -> Built:
    from .design import Alignment

    _fields(d, where, ("pis", "radii"), ("spiral_angles_deg", "spiral_lengths", "start_station"))
    pis = _points(d["pis"], f"{where}.pis", 3)
    count = len(pis) - 2
    radii = d["radii"]
    radii = [_number(r, f"{where}.radii[{i}]", positive=True) for i, r in enumerate(radii)] if isinstance(radii, list) else _number(radii, f"{where}.radii", positive=True)
    if isinstance(radii, list) and len(radii) != count:
        raise DesignError(f"{where}.radii: needs one radius per interior PI ({count}); got {len(radii)}")
    if ("spiral_angles_deg" in d) == ("spiral_lengths" in d):
        raise DesignError(f"{where}: give exactly one of spiral_angles_deg and spiral_lengths")
    kw = {}
    if "spiral_angles_deg" in d:
        kw["spiral_angles"] = _pairs(d["spiral_angles_deg"], f"{where}.spiral_angles_deg", count, _degrees)
    else:
        kw["spiral_lengths"] = _pairs(
            d["spiral_lengths"], f"{where}.spiral_lengths", count, lambda v, w: _number(v, w, positive=True)
        )
    start = _number(d.get("start_station", 0.0), f"{where}.start_station")
    alignment = Alignment.from_pis(pis, radii, start_station=start, **kw)
    return Built(d["name"], "alignment", alignment.chain, alignment)


def _circle_chain(d: dict, where: str) -> Built:
    from .design import circle_chain

    _fields(d, where, ("circles",))
    circles = d["circles"]
    if not isinstance(circles, list) or len(circles) < 2:
        raise DesignError(f"{where}.circles: must be a list of at least 2 circles; got {circles!r}")
    parsed = []
    for i, c in enumerate(circles):
        w = f"{where}.circles[{i}]"
        if not isinstance(c, dict) or set(c) != {"center", "radius"}:
            raise DesignError(f"{w}: must be {{\"center\": [x, y], \"radius\": r}}; got {c!r}")
        radius = _number(c["radius"], f"{w}.radius")
        if radius == 0:
            raise DesignError(f"{w}.radius: must be non-zero (its sign is the travel sense); got 0")
        parsed.append((_point(c["center"], f"{w}.center"), radius))
    result = circle_chain(parsed)
    return Built(d["name"], "circle_chain", result.chain, result)


def _rounded(d: dict, where: str) -> Built:
    from .design import round_corners

    _fields(d, where, ("points",), ("curvature", "max_curvature", "method"))
    points = _points(d["points"], f"{where}.points", 3)
    if "curvature" in d and "max_curvature" in d:
        raise DesignError(f"{where}: give at most one of curvature and max_curvature")
    kw = {k: _number(d[k], f"{where}.{k}", positive=True) for k in ("curvature", "max_curvature") if k in d}
    method = d.get("method", "walton-meek")
    if method not in ("walton-meek", "g2cbs"):
        raise DesignError(f"{where}.method: must be 'walton-meek' or 'g2cbs'; got {method!r}")
    result = round_corners(points, method=method, **kw)
    return Built(d["name"], "rounded_polyline", result.chain, result)


def _transition(d: dict, where: str) -> Built:
    from .core import transitions

    case = d.get("case")
    if case not in TRANSITION_ARGS:
        raise DesignError(f"{where}.case: must be one of {', '.join(TRANSITION_ARGS)}; got {case!r}")
    names = TRANSITION_ARGS[case]
    _fields(d, where, tuple(n for n in names if n not in OPTIONAL) + ("case",), tuple(n for n in names if n in OPTIONAL))
    args = {}
    for n in names:
        if n not in d:
            continue
        value = d[n]
        args[n] = _point(value, f"{where}.{n}") if isinstance(value, list) else _number(value, f"{where}.{n}")
    t = getattr(transitions, case)(**args)
    return Built(d["name"], f"transition ({t.kind})", Chain(t.spirals), t)


BUILDERS: dict[str, Callable[[dict, str], Built]] = {
    "alignment": _alignment,
    "circle_chain": _circle_chain,
    "rounded_polyline": _rounded,
    "transition": _transition,
}


def build(source: str | Path | dict) -> tuple[str, list[Built]]:
    """Validate and build every design of ``source``: (units, built designs).

    Raises:
        DesignError: the first malformed field or infeasible design, named as
            ``designs[i] (name)``.
    """
    units, designs = load(source)
    built = []
    for i, d in enumerate(designs):
        where = f"designs[{i}] ({d['name']})"
        try:
            built.append(BUILDERS[d["type"]](d, where))
        except DesignError:
            raise
        except (NoSolutionError, ValueError) as e:
            raise DesignError(f"{where}: {e}") from None
    return units, built


# -------------------------------------------------------------- writing


def write(
    built: list[Built], out: str | Path, units: str = "m", progress: Callable[[str], None] = print
) -> list[Path]:
    """Write STEP, IGES, DXF, SVG, plots, tables and a continuity report per design.

    Files go to a temporary folder first and move into ``out`` only when all
    of them were written.
    """
    from .cad.continuity import check_continuity
    from .export import export_dxf, export_iges, export_step, export_svg

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    with tempfile.TemporaryDirectory(dir=out) as tmp:
        stage = Path(tmp)
        for b in built:
            progress(f"  {b.name}: {b.kind}, {len(b.chain)} segments, length {b.chain.length:.6g} {units}")
            files = {ext: stage / f"{b.name}.{ext}" for ext in ("step", "igs", "dxf", "svg")}
            export_step(b.chain, files["step"])
            export_iges(b.chain, files["igs"])
            export_dxf(b.chain, files["dxf"])
            export_svg(b.chain, files["svg"])
            report = check_continuity(files["step"])
            b.notes["continuity"] = str(report.min_level)
            (stage / f"{b.name}_continuity.txt").write_text(report.format_table() + "\n", encoding="utf-8")
            _plots(b, stage)
            if hasattr(b.source, "to_csv"):
                b.source.to_csv(stage / f"{b.name}_stations.csv")
        for path in sorted(stage.iterdir()):
            target = out / path.name
            shutil.move(str(path), target)
            written.append(target)
    return written


def _plots(b: Built, stage: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plots import plot_curvature, plot_plan

    for suffix, plot in (("plan", plot_plan), ("curvature", plot_curvature)):
        fig = plot(b.chain)
        fig.suptitle(f"{b.name} — {b.kind}")
        fig.savefig(stage / f"{b.name}_{suffix}.png", dpi=110)
        plt.close(fig)


def summary(built: list[Built], units: str = "m") -> str:
    """One line per design: kind, segments, length, peak |κ| and the checked continuity."""
    import numpy as np

    head = f"{'design':14} {'kind':30} {'segments':>8} {'length ' + units:>12} {'max |κ|':>10} {'continuity':>10}"
    lines = [head, "-" * len(head)]
    for b in built:
        s = np.linspace(0, b.chain.length, 4001)
        peak = float(np.abs(b.chain.curvature_at(s)).max())
        lines.append(
            f"{b.name:14} {b.kind:30} {len(b.chain):8d} {b.chain.length:12.3f} {peak:10.5f} {b.notes.get('continuity', '-'):>10}"
        )
    return "\n".join(lines)
