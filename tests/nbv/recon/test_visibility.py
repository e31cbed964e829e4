"""Visible-surface coverage against analytic answers: faces of a cube, and an occluder."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from nbv.recon.visibility import seen_mask, visible_coverage
from render.camera import UAVCamera
from render.viewpoint import Viewpoint, viewpoint_to_c2w

CAMERA = UAVCamera(96, 72, focal_mm=20.0)  # a 1 m cube at 3 m fills well under the frame
CUBE = trimesh.creation.box((1, 1, 1))


def pose(azimuth: float, elevation: float = 0.0, radius: float = 3.0) -> np.ndarray:
    return viewpoint_to_c2w(Viewpoint(radius, azimuth, elevation), np.zeros(3))


def test_a_cube_face_on_shows_one_face_and_opposite_views_two():
    # The depth slack also counts a band of that width along the 4 side faces: 4 x 0.005 / 6 of the area.
    def coverage(poses: list[np.ndarray]) -> float:
        return visible_coverage([CUBE], CUBE, CAMERA, poses, points=12_000, tolerance_m=0.005)

    band = 4 * 0.005 / 6
    assert coverage([pose(0.0)]) == pytest.approx(1 / 6 + band, abs=0.01)
    assert coverage([pose(0.0), pose(np.pi)]) == pytest.approx(2 / 6 + 2 * band, abs=0.01)
    around = [pose(k * np.pi / 2) for k in range(4)] + [pose(0.0, elevation=1.5)]
    assert coverage(around) == pytest.approx(5 / 6, abs=0.01)


def test_an_occluder_hides_the_target():
    wall = trimesh.creation.box((0.1, 3, 3))
    wall.apply_translation((1.5, 0, 0))  # between the camera at +x and the cube
    assert visible_coverage([CUBE, wall], CUBE, CAMERA, [pose(0.0)], points=3000) == 0.0


def test_points_behind_the_camera_or_outside_the_image_are_not_seen():
    depth = np.full((CAMERA.height, CAMERA.width), 10.0, dtype=np.float32)
    c2w = pose(0.0)  # at (3, 0, 0) looking at the origin
    points = np.array([[0.0, 0.0, 0.0], [6.0, 0.0, 0.0], [0.0, 50.0, 0.0]])
    assert seen_mask(points, depth, CAMERA.K, c2w, 0.02).tolist() == [True, False, False]
