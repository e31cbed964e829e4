"""The report's maths on hand-made poses: a model that is the truth under a similarity scores zero, a
view turned by a known angle shows it (alone, and in every pair it belongs to), centre errors scale
to the scan radius, and fewer than 3 views or collinear centres give no fit, said so."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from nbv.sfm.report import pose_errors, relative_rotation_errors_deg
from render.viewpoint import Viewpoint, viewpoint_to_c2w

CENTER = np.array([0.0, 0.0, 0.5])


def ring(count: int, radius: float = 2.0) -> np.ndarray:
    """(count, 4, 4) true camera-to-world poses on a ring at 30 degrees elevation, 40 degrees apart."""
    return np.stack([viewpoint_to_c2w(Viewpoint(radius, math.radians(40.0 * i), math.radians(30.0)), CENTER)
                     for i in range(count)])


def similar(poses: np.ndarray, scale: float, rotation: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """The poses in another frame, x -> scale * rotation @ x + shift: what an SfM model is."""
    out = poses.copy()
    out[:, :3, :3] = rotation @ poses[:, :3, :3]
    out[:, :3, 3] = scale * poses[:, :3, 3] @ rotation.T + shift
    return out


ROTATION = Rotation.from_euler("xyz", [10.0, 80.0, -35.0], degrees=True).as_matrix()


def test_the_truth_in_another_frame_has_no_error_and_the_inverse_scale():
    truth = ring(5)
    errors = pose_errors(truth, similar(truth, 0.25, ROTATION, np.array([3.0, 1.0, -2.0])), radius=2.0)
    assert errors["views"] == 5 and errors["scale"] == pytest.approx(4.0)
    assert errors["centre_error_cm"]["max"] < 1e-9
    assert errors["rotation_error_deg"]["max"] < 1e-5
    assert errors["relative_rotation_error_deg"]["max"] < 1e-5


def test_one_view_turned_by_10_degrees_shows_alone_and_in_its_pairs():
    truth = ring(4)
    model = similar(truth, 2.0, ROTATION, np.zeros(3))
    model[2, :3, :3] = model[2, :3, :3] @ Rotation.from_euler("y", 10.0, degrees=True).as_matrix()
    errors = pose_errors(truth, model, radius=2.0)
    assert errors["centre_error_cm"]["max"] < 1e-9  # the fit uses the centres only
    assert errors["rotation_error_deg"] == pytest.approx({"mean": 2.5, "median": 0.0, "max": 10.0}, abs=1e-6)
    # 6 pairs, 3 holding view 2: errors 0, 0, 0, 10, 10, 10
    assert errors["relative_rotation_error_deg"] == pytest.approx({"median": 5.0, "max": 10.0}, abs=1e-6)


def test_centre_errors_are_in_cm_and_in_percent_of_the_radius():
    truth = ring(4, radius=2.0)
    model = truth.copy()
    model[:, :3, 3] += np.array([0.0, 0.0, 0.03])  # a shift the fit removes
    model[0, :3, 3] = 2.0 * model[0, :3, 3] - model[1, :3, 3]  # view 0 moved off the ring
    errors = pose_errors(truth, model, radius=2.0)
    cm, pct = errors["centre_error_cm"], errors["centre_error_pct_radius"]
    assert cm["max"] > 1.0
    assert pct == pytest.approx({k: v / 200.0 * 100.0 for k, v in cm.items()})
    assert cm["mean"] <= cm["max"] and cm["median"] <= cm["max"]


def test_relative_rotation_errors_of_one_view_are_empty():
    assert relative_rotation_errors_deg(ring(1)[:, :3, :3], ring(1)[:, :3, :3]).shape == (0,)


def test_collinear_centres_have_no_fit():
    line = np.stack([np.eye(4)] * 3)
    line[:, :3, 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    with pytest.raises(ValueError, match="one line"):
        pose_errors(line, line, radius=1.0)
