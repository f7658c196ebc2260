"""The samples writer's batch quadrature and CSV rows against the one-curve ``bezier.arc_length`` and the row-by-row text."""

import numpy as np
import pytest

from spiral_cad.core import bezier
from spiral_cad.core.kinds import SPIRAL
from spiral_cad.design import Alignment, round_corners
from spiral_cad.io.samples import COLUMNS, _Rows, sample_path, write_samples

RUN = [(0, 0, 0), (100, 0, 0), (100, 80, 30), (0, 80, 60), (0, 0, 90)]


def _chains():
    yield round_corners(RUN, max_deviation=2.0).chain  # in space
    yield round_corners([(0, 0), (40, 0), (40, 30), (-10, 35), (0, 90)], max_deviation=0.5).chain  # in the plane
    yield Alignment.from_pis([(0, 0), (300, 60), (560, -40), (820, 90)], radii=[220, 260], spiral_angles=0.12, units="m").chain
    small = np.array([(0, 0), (1, 0), (1, 2), (3, 2.5)]) * 1e-2 + 1e3  # small and far from the origin
    yield round_corners(small, max_deviation=1e-4).chain


@pytest.mark.parametrize("index", range(4))
def test_batch_arc_lengths_equal_the_one_curve_rule(index):
    chain = list(_chains())[index]
    rows = _Rows(chain)
    spirals = np.flatnonzero(rows.kind == SPIRAL)
    assert len(spirals) > 0
    owner = np.repeat(spirals, 7)
    u = np.tile(np.linspace(0.0, 1.0, 7), len(spirals))
    batch = rows._arc_lengths(owner, u)
    one = np.array([bezier.arc_length(rows.cp[i], t) for i, t in zip(owner.tolist(), u.tolist())])
    assert np.all(one[u > 0] > 0.0)
    assert np.allclose(batch, one, rtol=1e-12, atol=0.0)
    # the stations written are the old ones: the many-curve call of arc_length
    s = rows.frames(owner, u)[0]
    old = rows.stations[owner] + np.minimum(bezier.arc_length(rows.cp[owner], u), rows.lengths[owner])
    assert np.allclose(s, old, rtol=1e-12, atol=1e-15 * chain.length)


def test_csv_rows_are_the_row_by_row_text(tmp_path):
    chain = round_corners(RUN, max_deviation=2.0).chain
    count = write_samples(chain, tmp_path / "run.csv", chord_tolerance=0.01)
    table = sample_path(chain, chord_tolerance=0.01)
    head = ",".join(f"{name} [{dimension.replace('L', 'mm')}]" for name, dimension in COLUMNS)
    body = "\n".join(",".join(map(repr, row)) for row in (table + 0.0).tolist())
    assert count == len(table) > 50
    assert (tmp_path / "run.csv").read_text(encoding="utf-8") == f"{head}\n{body}\n"
