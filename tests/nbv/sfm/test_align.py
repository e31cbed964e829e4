"""Umeyama's similarity fit: a hand-made similarity recovered exactly, optimality against a generic
least-squares solver, reflections refused as rotations, degenerate inputs named."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from nbv.sfm.align import umeyama

ROTATION = Rotation.from_euler("zyx", [40.0, -25.0, 70.0], degrees=True).as_matrix()
POINTS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0], [1.0, 1.0, 1.0]])


def test_a_known_similarity_is_recovered_exactly():
    dst = 0.37 * POINTS @ ROTATION.T + np.array([2.0, -1.0, 5.0])
    fit = umeyama(POINTS, dst)
    assert fit.scale == pytest.approx(0.37, abs=1e-12)
    assert np.allclose(fit.rotation, ROTATION, atol=1e-12)
    assert np.allclose(fit.translation, [2.0, -1.0, 5.0], atol=1e-12)
    assert np.allclose(fit.apply(POINTS), dst, atol=1e-12)


def test_noisy_points_get_the_least_squares_optimum():
    rng = np.random.default_rng(3)
    src = rng.normal(size=(20, 3))
    dst = 1.8 * src @ ROTATION.T + [0.5, 0.0, -2.0] + rng.normal(scale=0.05, size=src.shape)
    fit = umeyama(src, dst)

    def residuals(p: np.ndarray) -> np.ndarray:
        rot = Rotation.from_rotvec(p[1:4]).as_matrix()
        return (np.exp(p[0]) * src @ rot.T + p[4:] - dst).ravel()

    start = np.concatenate([[0.0], Rotation.from_matrix(ROTATION).as_rotvec() + 0.1, np.zeros(3)])
    best = least_squares(residuals, start, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    ours = ((fit.apply(src) - dst) ** 2).sum()
    assert ours == pytest.approx((best.fun**2).sum(), rel=1e-9)
    assert fit.scale == pytest.approx(np.exp(best.x[0]), rel=1e-6)


def test_a_mirror_image_gets_a_proper_rotation():
    mirrored = POINTS * [1.0, 1.0, -1.0]
    fit = umeyama(POINTS, mirrored)
    assert np.linalg.det(fit.rotation) == pytest.approx(1.0)
    assert np.allclose(fit.rotation @ fit.rotation.T, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("src, dst, message", [
    (POINTS[:2], POINTS[:2], "at least 3 point pairs"),
    (POINTS, POINTS[:4], "of one shape"),
    (np.outer(np.arange(4.0), [1.0, 2.0, 3.0]), np.outer(np.arange(4.0), [1.0, 0.0, 0.0]), "one line"),
])
def test_degenerate_point_sets_are_refused_by_name(src, dst, message):
    with pytest.raises(ValueError, match=message):
        umeyama(src, dst)
