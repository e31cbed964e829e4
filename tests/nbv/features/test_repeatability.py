"""Keypoint repeatability against hand-worked projections of a fronto-parallel plane."""

import numpy as np
import pytest

from nbv.features.repeatability import carry_keypoints, match_descriptors, match_inlier_ratio, repeatability

K = np.array([[50.0, 0.0, 31.5], [0.0, 50.0, 23.5], [0.0, 0.0, 1.0]])
PLANE = np.full((48, 64), 2.0)  # a wall 2 m in front of camera A


def shifted(dx_m):
    """Camera B: camera A moved dx_m metres along its x axis (OpenCV: right)."""
    pose = np.eye(4)
    pose[0, 3] = dx_m
    return pose


def test_a_sideways_step_moves_keypoints_by_fx_times_step_over_depth():
    keypoints = np.array([[10.0, 5.0], [40.0, 30.0]])
    pixels, seen = carry_keypoints(keypoints, PLANE, K, np.eye(4), K, shifted(0.1))
    # u' = u - fx * 0.1 / 2 = u - 2.5 pixels; rows unchanged.
    np.testing.assert_allclose(pixels, [[7.5, 5.0], [37.5, 30.0]])
    assert seen.all()
    assert repeatability(keypoints, pixels + [0.8, 0.0], PLANE, K, np.eye(4), K, shifted(0.1)) == 1.0
    assert repeatability(keypoints, pixels[:1], PLANE, K, np.eye(4), K, shifted(0.1)) == 0.5


def test_points_leaving_the_image_without_depth_or_hidden_do_not_count():
    keypoints = np.array([[1.0, 5.0], [20.0, 10.0], [30.0, 20.0]])
    depth = PLANE.copy()
    depth[20, 30] = 0.0  # the third keypoint sees the sky
    _, seen = carry_keypoints(keypoints, depth, K, np.eye(4), K, shifted(0.1))
    assert seen.tolist() == [False, True, False]  # the first lands at u = -1.5, outside B
    occluder = np.full((48, 64), 1.0)  # something 1 m in front of B hides the wall
    _, hidden = carry_keypoints(keypoints, depth, K, np.eye(4), K, shifted(0.1), occluder)
    assert not hidden.any()
    assert repeatability(keypoints, keypoints, depth, K, np.eye(4), K, shifted(0.1), occluder) == 0.0


@pytest.mark.parametrize("tol, expected", [(0.5, 0.0), (1.0, 1.0)])
def test_the_tolerance_is_a_pixel_distance(tol, expected):
    found = np.array([[10.0, 10.0]])
    assert repeatability(found, found + [0.6, 0.6], PLANE, K, np.eye(4), tol_px=tol) == expected


def test_matches_are_mutual_nearest_neighbours_that_pass_the_ratio_test():
    a = np.array([[1.0, 0.0], [0.0, 1.0], [0.7, 0.7]])
    b = np.array([[0.0, 1.0], [1.0, 0.05], [0.95, 0.0]])
    # a0 -> b2 (0.05 vs b1 at 0.05: tie fails the ratio); a1 -> b0; a2's nearest b1 prefers a0 -> not mutual.
    pairs = match_descriptors(a, b)
    assert pairs.tolist() == [[1, 0]]
    assert match_descriptors(a, b[:0]).shape == (0, 2)


def test_the_inlier_ratio_counts_matches_landing_at_the_carried_point():
    keypoints = np.array([[10.0, 5.0], [40.0, 30.0]])
    desc = np.eye(2)
    pixels, _ = carry_keypoints(keypoints, PLANE, K, np.eye(4), K, shifted(0.1))
    step = (PLANE, K, np.eye(4), K, shifted(0.1))
    right = match_inlier_ratio(keypoints, desc, pixels + [0.5, 0.0], desc, *step)
    wrong = match_inlier_ratio(keypoints, desc, pixels[::-1], desc, *step)
    half = match_inlier_ratio(keypoints, desc, np.array([pixels[0], pixels[1] + [3.0, 0.0]]), desc, PLANE, K,
                              np.eye(4), K, shifted(0.1))
    assert (right, wrong, half) == (1.0, 0.0, 0.5)
