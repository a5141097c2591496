"""regrasp.polygon: ear clipping of non-convex outlines tiles them exactly (the star-shaped
property test is tests/test_viewer.py's)."""

from __future__ import annotations

import numpy as np
import pytest

from regrasp.polygon import signed_area, triangulate


def tri_areas(p, t):
    e1, e2 = p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]
    return (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / 2


@pytest.mark.parametrize("p", [
    [[0, 0], [3, 0], [3, 1], [2, 1], [2, 3], [1, 3], [1, 1], [0, 1]],  # a T upside down
    [[0, 0], [4, 0], [4, 3], [3, 3], [3, 1], [1, 1], [1, 3], [0, 3]],  # a U
    [[0, 0], [1, 0], [1, 1], [0, 1]],
])
def test_non_convex_outlines_are_tiled(p):
    p = np.asarray(p, float)
    t = np.asarray(triangulate(p))
    a = tri_areas(p, t)
    assert len(t) == len(p) - 2 and np.all(a > 0) and a.sum() == pytest.approx(signed_area(p))


def test_signed_area_is_positive_counter_clockwise():
    sq = np.array([[0, 0], [2, 0], [2, 1], [0, 1]], float)
    assert signed_area(sq) == pytest.approx(2) and signed_area(sq[::-1]) == pytest.approx(-2)
