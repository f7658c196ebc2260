"""Zebra stripes and curvature maps as figures: what they are drawn from and what they refuse."""

from __future__ import annotations

import math

import pytest

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402

from spiral_cad.app.zebra import VIEW, plot_curvature_map, plot_zebra  # noqa: E402
from spiral_cad.cad.mesh import face_mesh  # noqa: E402


@pytest.fixture(scope="module")
def sphere():
    return face_mesh(bd.Sphere(5), angle=0.2)


def _pixels(fig) -> np.ndarray:
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3] / 255.0


def test_zebra_of_a_sphere_draws_rings_of_both_colours(sphere):
    image = _pixels(plot_zebra(sphere, stripes=4, view=(0, 0, 1), across=(1, 0, 0)))
    dark, light = (image < 0.2).all(axis=2).mean(), (image > 0.9).all(axis=2).mean()
    assert dark > 0.05 and light > 0.05


def test_curvature_map_of_a_sphere_is_one_colour_with_its_scale(sphere):
    fig = plot_curvature_map(sphere, title="sphere")
    assert len(fig.axes) == 2 and "1/mm" in fig.axes[1].get_ylabel()  # the colour bar names the unit
    assert np.allclose(np.asarray(fig.axes[0].images[0].get_array().compressed()), 0.2, atol=1e-9)  # 1/r everywhere


@pytest.mark.parametrize(
    ("call", "message"),
    [(lambda m: plot_zebra(m, stripes=0), "stripes"), (lambda m: plot_zebra(m, pixels=True), "pixels"),
     (lambda m: plot_zebra(m, view=(0, 0, 0)), "view"), (lambda m: plot_zebra(m, across=(math.nan, 0, 1)), "across"),
     (lambda m: plot_curvature_map(m, kind="max"), "kind"), (lambda m: face_mesh(bd.Box(1, 1, 1), angle=0), "angle")],
)  # fmt: skip
def test_bad_arguments_raise_value_error_naming_them(sphere, call, message):
    with pytest.raises(ValueError, match=message):
        call(sphere)


def test_an_open_dome_seen_from_behind_is_drawn_not_left_blank():
    dome = next(f for f in bd.Sphere(5).faces()).split(bd.Plane.XY, keep=bd.Keep.TOP)  # the upper half, open below
    image = _pixels(plot_zebra(face_mesh(dome, angle=0.2), stripes=4, view=(0.2, 0.1, -1), across=(1, 0, 0)))
    dark, light = (image < 0.2).all(axis=2).mean(), (image > 0.9).all(axis=2).mean()
    assert dark > 0.05 and light > 0.05  # seen from inside: stripes of both colours


def test_a_face_seen_edge_on_warns_that_nothing_is_visible():
    with pytest.warns(UserWarning, match="nothing is visible"):
        plot_zebra(face_mesh(bd.Face.make_rect(10, 10)), view=(1, 0, 0))


def test_the_mesh_keeps_below_its_triangle_cap_and_follows_the_pictures_size():
    part = bd.fillet(bd.Box(40, 20, 16).edges(), 6)
    fine = face_mesh(part)
    capped = face_mesh(part, max_triangles=5_000)
    assert len(fine.triangles) > 20_000 and len(capped.triangles) <= 5_000
    coarse = face_mesh(part, pixels=100, angle=0.3)
    assert len(coarse.triangles) < len(face_mesh(part, angle=0.3).triangles)  # deflection of half a pixel


def test_curvature_map_is_one_image_whatever_the_mesh(sphere):
    fig = plot_curvature_map(sphere, pixels=200)
    assert len(fig.axes[0].images) == 1 and not fig.axes[0].collections
    assert max(fig.axes[0].images[0].get_array().shape) == 200


def _stripe_kinks(part, view=VIEW) -> list[float]:
    """The jump, in degrees, of the stripe borders' direction across each visible vertical edge of a
    prism, measured on the drawn picture: the borders' direction (structure tensor of the grey levels'
    Sobel gradient) in strips 1–2 and 3–4 pixels each side of the edge, extrapolated to the edge."""
    from scipy import ndimage

    fig = plot_zebra(part, view=view)
    image = fig.axes[0].images[0]
    grey = np.nan_to_num(np.asarray(image.get_array(), dtype=float), nan=1.0)
    height, width = grey.shape
    left, right_, bottom, top = image.get_extent()
    v = np.asarray(view, dtype=float) / np.linalg.norm(view)
    right = np.cross((0.0, 0.0, 1.0), v)
    right /= np.linalg.norm(right)
    up = np.cross(v, right)  # the picture's axes: orthographic along the view, z up

    def pixel(p):
        return np.array([(p @ right - left) / (right_ - left) * width - 0.5, (p @ up - bottom) / (top - bottom) * height - 0.5])

    gx, gy = ndimage.sobel(grey, axis=1), ndimage.sobel(grey, axis=0)
    kinks = []
    for edge in part.edges().filter_by(bd.Axis.Z):
        middle = edge.center()
        if min(np.array(tuple(f.normal_at(middle))) @ v for f in part.faces() if any(edge == e for e in f.edges())) < 0.15:
            continue  # not seen, or seen at a grazing angle
        a, b = (pixel(np.array(tuple(edge.position_at(t)))) for t in (0.15, 0.85))
        along = (b - a) / np.linalg.norm(b - a)
        normal = np.array([-along[1], along[0]])
        steps = np.linspace(0.0, 1.0, int(np.linalg.norm(b - a)))[:, None]

        def direction(side, offsets):
            at = np.vstack([a + steps * (b - a) + side * o * normal for o in offsets])
            j, i = np.rint(at).astype(int).T
            x, y = gx[i, j], gy[i, j]
            return 0.5 * math.atan2(2.0 * (x * y).sum(), (x * x).sum() - (y * y).sum())

        def wrapped(angle):
            return (angle + math.pi / 2) % math.pi - math.pi / 2

        at_edge = []
        for side in (-1.0, 1.0):
            near, far = direction(side, (1, 2)), direction(side, (3, 4))
            at_edge.append(near - 0.75 * wrapped(far - near))  # strips centred 1.5 and 3.5 px out: on to 0
        kinks.append(abs(math.degrees(wrapped(at_edge[1] - at_edge[0]))))
    return kinks


def test_zebra_stripes_kink_at_a_g1_edge_and_not_at_a_g2_one():
    """The picture's job, measured on its pixels: across each visible edge where a side meets a circular
    fillet (G1) the stripe borders turn by 20° or more at once, and across each edge of the same box
    with G2 corners (ContinuousRectangle: plane–spiral–arc–spiral) by under 8°."""
    from spiral_cad.build123d import ContinuousRectangle

    g1 = _stripe_kinks(bd.fillet(bd.Box(60, 40, 10).edges().filter_by(bd.Axis.Z), 12))
    g2 = _stripe_kinks(bd.extrude(ContinuousRectangle(60, 40, 12), 10))
    assert len(g1) >= 3 and len(g2) >= 6
    assert min(g1) >= 20.0 and max(g2) < 8.0, (g1, g2)
