import math

import numpy as np
import pytest

from render.camera import UAVCamera


def test_intrinsics_follow_the_36mm_sensor_and_opencv_centres():
    cam = UAVCamera(width=320, height=240, focal_mm=36.0)
    np.testing.assert_allclose(cam.K, [[320, 0, 159.5], [0, 320, 119.5], [0, 0, 1]])
    assert cam.fov_x_deg == pytest.approx(2 * math.degrees(math.atan(0.5)))
    assert cam.fov_y_deg == pytest.approx(2 * math.degrees(math.atan(120 / 320)))


def test_with_resolution_keeps_the_field_of_view():
    cam = UAVCamera(320, 240, 35.0).with_resolution(640, 480)
    assert cam.fov_x_deg == pytest.approx(UAVCamera(320, 240, 35.0).fov_x_deg)
    assert cam.K[0, 2] == 319.5


@pytest.mark.parametrize("kwargs, field", [
    ({"width": 0}, "width"), ({"height": -5}, "height"), ({"focal_mm": 0.0}, "focal_mm"),
    ({"focal_mm": -35.0}, "focal_mm"), ({"focal_mm": float("nan")}, "focal_mm"),
    ({"near_m": 2.0, "far_m": 1.0}, "near_m"),
])
def test_bad_camera_values_name_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        UAVCamera(**kwargs)
