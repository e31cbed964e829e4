import math

import numpy as np
import pytest

from render.viewpoint import Viewpoint, c2w_to_viewpoint, opencv_to_opengl, validate_pose, viewpoint_to_c2w

CENTER = np.array([0.1, -0.2, 0.4])


@pytest.mark.parametrize("az, el", [(0.0, 0.0), (1.0, 0.5), (4.0, -0.3), (2.0, math.pi / 2)])
def test_camera_sits_on_the_sphere_and_looks_at_the_centre(az, el):
    c2w = viewpoint_to_c2w(Viewpoint(2.5, az, el), CENTER)
    rot, pos = c2w[:3, :3], c2w[:3, 3]
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rot) == pytest.approx(1.0)
    assert np.linalg.norm(pos - CENTER) == pytest.approx(2.5)
    np.testing.assert_allclose(rot[:, 2], (CENTER - pos) / 2.5, atol=1e-12)
    assert rot[2, 0] == pytest.approx(0.0)  # x (image right) stays horizontal
    assert rot[2, 1] <= 1e-12  # y (image down) never points up


def test_known_pose_from_the_positive_x_axis():
    c2w = viewpoint_to_c2w(Viewpoint(2.0, 0.0, 0.0), np.zeros(3))
    # At +x looking at -x with z up: image right is +y, image down is -z.
    np.testing.assert_allclose(c2w[:3, :3], [[0, 0, -1], [1, 0, 0], [0, -1, 0]], atol=1e-12)
    np.testing.assert_allclose(c2w[:3, 3], [2, 0, 0], atol=1e-12)


def test_viewpoint_round_trip():
    view = Viewpoint(1.7, 5.5, 0.8)
    back = c2w_to_viewpoint(viewpoint_to_c2w(view, CENTER), CENTER)
    np.testing.assert_allclose(back.as_array(), view.as_array(), atol=1e-12)


def test_azimuth_wraps_into_range():
    assert Viewpoint(1.0, -math.pi / 2, 0.0).azimuth == pytest.approx(1.5 * math.pi)


def test_opengl_conversion_is_an_involution_flipping_y_and_z():
    c2w = viewpoint_to_c2w(Viewpoint(2.0, 1.0, 0.3), CENTER)
    gl = opencv_to_opengl(c2w)
    np.testing.assert_allclose(gl[:3, 1], -c2w[:3, 1])
    np.testing.assert_allclose(gl[:3, 2], -c2w[:3, 2])
    np.testing.assert_allclose(opencv_to_opengl(gl), c2w)


@pytest.mark.parametrize("bad, message", [
    (lambda p: p.__setitem__((0, 3), np.nan), "NaN"),
    (lambda p: p.__setitem__((1, 3), np.inf), "NaN or infinite"),
    (lambda p: p.__setitem__((0, 0), 3.0), "rotation"),
])
def test_bad_poses_are_rejected(bad, message):
    pose = np.eye(4)
    bad(pose)
    with pytest.raises(ValueError, match=message):
        validate_pose(pose)


def test_bad_viewpoints_are_rejected():
    with pytest.raises(ValueError, match="NaN"):
        Viewpoint(1.0, float("nan"), 0.0)
    with pytest.raises(ValueError, match="radius"):
        Viewpoint(0.0, 0.0, 0.0)
