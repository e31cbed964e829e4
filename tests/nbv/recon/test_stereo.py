"""Plane-sweep stereo against analytic answers: a textured plane seen by two cameras side by side gives its
depth where both see it; a step in depth keeps both levels and (all but a few pixels of) the strip one view
cannot see is left unmeasured; blank images measure nothing; bad settings are refused by their messages."""

from __future__ import annotations

import numpy as np
import pytest

from nbv.recon.stereo import (
    StereoConfig,
    agreed_depth,
    box_depth_range,
    box_stereo_depth,
    grayscale,
    sweep,
    two_view_depth,
    within_box,
)
from render.camera import UAVCamera, pixel_rays

CAMERA = UAVCamera(160, 120)
BASELINE = 0.25


def texture(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A smooth, non-repeating pattern on the plane (sum of 24 seeded sinusoids, wavelengths 4 to 30 cm)."""
    rng = np.random.default_rng(7)
    value = np.zeros_like(x)
    for _ in range(24):
        angle, wavelength, phase = rng.uniform(0, np.pi), rng.uniform(0.04, 0.3), rng.uniform(0, 2 * np.pi)
        value += np.sin(2 * np.pi * (x * np.cos(angle) + y * np.sin(angle)) / wavelength + phase)
    return 0.5 + value / 12.0


def pose(x: float) -> np.ndarray:
    """A camera at (x, 0, 0) looking along +z (OpenCV axes are the world's)."""
    c2w = np.eye(4)
    c2w[0, 3] = x
    return c2w


def image(surfaces: list[tuple[float, float]], camera_x: float) -> tuple[np.ndarray, np.ndarray]:
    """What a camera at `camera_x` sees of textured fronto-parallel planes (depth z, from world x on to +inf),
    and its z-depth: the nearest plane a ray meets (exact: planes parallel to the image)."""
    rays = pixel_rays(CAMERA.K, CAMERA.width, CAMERA.height)
    best, shade = np.full(rays.shape[:2], np.inf), np.zeros(rays.shape[:2])
    for z, start in surfaces:
        x, y = camera_x + rays[..., 0] * z, rays[..., 1] * z
        hit = (x >= start) & (z < best)
        best[hit], shade[hit] = z, texture(x, y)[hit]
    return shade, best


def test_a_textured_plane_gives_its_depth_where_both_views_see_it():
    plane = [(2.0, -np.inf)]
    (left, truth), (right, _) = image(plane, 0.0), image(plane, BASELINE)
    depth, other = two_view_depth(left, right, CAMERA.K, pose(0.0), pose(BASELINE), 1.0, 4.0)
    error, kept = np.abs(depth - truth) / truth, np.isfinite(depth)
    shift = CAMERA.K[0, 0] * BASELINE / 2.0  # the disparity, 19.4 pixels
    assert not kept[:, :int(shift)].any()  # the left strip is off the other image: not measured
    assert kept[:, int(shift) + 4:].mean() > 0.95
    assert np.nanquantile(error, 0.99) < 0.005 and np.nanmax(error) < 0.03
    assert np.nanmax(np.abs(other - 2.0)) < 0.06 and not np.isfinite(other[:, -int(shift):]).any()


def test_a_step_keeps_both_levels_and_not_the_strip_one_view_cannot_see():
    step = [(2.5, -np.inf), (1.5, 0.3)]  # a near plane on the right, its edge at x = 0.3, before a far one
    (left, truth), (right, _) = image(step, 0.0), image(step, BASELINE)
    depth, _ = two_view_depth(left, right, CAMERA.K, pose(0.0), pose(BASELINE), 1.0, 4.0)
    kept, wrong = np.isfinite(depth), np.abs(depth - truth) / truth > 0.02
    edge = int(np.argmax(truth[0] == 1.5))  # the first near column
    columns = np.arange(CAMERA.width)
    assert (kept & wrong).sum() < 0.01 * kept.sum()  # a few wrong: near the edge and what it hides
    assert not (kept & wrong)[:, (columns < edge - 16) | (columns > edge + 4)].any()
    for level in (1.5, 2.5):
        assert (kept & (truth == level)).sum() > 0.8 * ((truth == level) & (columns >= 24)).sum() - 12 * 120
    # far points at x in (1/3, 1/2) are seen by the left camera and hidden from the right one by the edge
    far_x = pixel_rays(CAMERA.K, CAMERA.width, CAMERA.height)[..., 0] * 2.5
    hidden = (truth == 2.5) & (far_x > 1 / 3 + 0.01) & (far_x < 0.49)
    assert hidden.sum() > 8 * 120 and kept[hidden].mean() < 0.05


def test_blank_images_measure_nothing():
    blank = np.zeros((CAMERA.height, CAMERA.width))
    depth, other = two_view_depth(blank, blank, CAMERA.K, pose(0.0), pose(BASELINE), 1.0, 4.0)
    assert np.isnan(depth).all() and np.isnan(other).all()
    best, correlation = sweep(blank, blank, CAMERA.K, pose(0.0), pose(BASELINE), 1.0, 4.0)
    assert np.isnan(best).all() and (correlation == -1).all()


def test_box_range_grayscale_and_refusals():
    near, far = box_depth_range(np.array([-1.0, -1, 2]), np.array([1.0, 1, 3]), pose(0.0))
    assert (near, far) == (2.0, 3.0)
    assert box_depth_range(np.array([-1.0, -1, -3]), np.array([1.0, 1, 3]), pose(0.0))[0] == 0.05
    assert grayscale(np.full((1, 1, 3), 255, np.uint8))[0, 0] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="odd window"):
        StereoConfig(window=6)
    with pytest.raises(ValueError, match="0 < near < far"):
        sweep(np.zeros((4, 4)), np.zeros((4, 4)), CAMERA.K, pose(0.0), pose(BASELINE), 2.0, 1.0)


def test_pairs_agree_on_a_depth_by_majority_and_a_lone_match_is_dropped():
    n = np.nan
    first = np.array([[2.0, 2.0, n, 3.0, n]])
    second = np.array([[2.02, 2.5, n, n, 1.0]])
    third = np.array([[1.99, 3.0, 4.0, 3.01, n]])
    agreed = agreed_depth([first, second, third], 0.02)
    # all three within 2 % of 2.0: their mean; three pairs disagree; one pair only; two agree; one only
    np.testing.assert_allclose(agreed, [[(2.0 + 2.02 + 1.99) / 3, n, n, (3.0 + 3.01) / 2, n]], rtol=1e-6)
    alone = agreed_depth([first, second, third], 0.02, least=1)
    np.testing.assert_allclose(alone, [[(2.0 + 2.02 + 1.99) / 3, 2.0, 4.0, (3.0 + 3.01) / 2, 1.0]], rtol=1e-6)


def test_the_box_sweep_is_the_sweep_between_the_box_depths_from_either_view():
    left, right = image([(2.0, 0.0)], 0.0)[0], image([(2.0, 0.0)], BASELINE)[0]
    lower, upper = np.array([-2.0, -2.0, 1.5]), np.array([2.0, 2.0, 3.0])
    near = min(box_depth_range(lower, upper, p)[0] for p in (pose(0.0), pose(BASELINE)))
    far = max(box_depth_range(lower, upper, p)[1] for p in (pose(0.0), pose(BASELINE)))
    boxed = box_stereo_depth(left, right, CAMERA.K, pose(0.0), pose(BASELINE), lower, upper)
    swept = two_view_depth(left, right, CAMERA.K, pose(0.0), pose(BASELINE), near, far)
    for a, b in zip(boxed, swept, strict=True):
        np.testing.assert_array_equal(a, b)


def test_depths_outside_the_box_grown_by_the_tolerance_are_dropped():
    depth = np.full((CAMERA.height, CAMERA.width), 2.0, np.float32)
    depth[:, 80:], depth[:10] = 4.0, np.nan  # right half behind the box; top rows not measured
    lower, upper = np.array([-10.0, -10.0, 1.0]), np.array([10.0, 10.0, 3.0])  # z-depths 1 to 3 m
    kept = within_box(depth, CAMERA.K, pose(0.0), lower, upper)
    assert np.all(kept[10:, :80] == 2.0) and np.isnan(kept[:, 80:]).all() and np.isnan(kept[:10]).all()
    grown = within_box(depth, CAMERA.K, pose(0.0), lower, upper, tolerance=1.0)  # 4 m is on the grown box
    np.testing.assert_array_equal(grown[10:], depth[10:])
    moved = within_box(depth, CAMERA.K, pose(7.0), lower, upper)  # 7 m to the side: x from about 6 to 8
    assert np.all(moved[10:, :80] == 2.0)
    assert np.isnan(within_box(depth, CAMERA.K, pose(12.0), lower, upper)).all()  # x past 10: all outside
