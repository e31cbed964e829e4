"""Keypoint repeatability against hand-worked projections of a fronto-parallel plane."""

import numpy as np
import pytest

from nbv.features.repeatability import carry_keypoints, repeatability

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
