"""What a structure-from-motion result is worth: registration, points, reprojection error and, against
the true poses, camera-centre and rotation errors after a similarity fit (`nbv.sfm.align`).

Centre errors are in centimetres and as a percentage of the scan radius (the mean distance of the true
centres from the scene centre). Rotation error: the angle between a view's true camera-to-world
rotation and its estimate carried through the fit's rotation. Relative rotation error: over every pair
of registered views, the angle between the true and the estimated rotation from one to the other;
it needs no fit, and a model that folds (two sides of a building matched onto each other) shows as
large relative errors between far-apart views while neighbours agree.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pycolmap
from scipy.spatial.transform import Rotation

from nbv.sfm.align import umeyama


def rotation_angles_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N,) angles in degrees of the rotations a_i^T b_i between (N, 3, 3) rotation stacks.

    Example:
        >>> z90 = Rotation.from_euler("z", 90, degrees=True).as_matrix()
        >>> rotation_angles_deg(np.eye(3)[None], z90[None]).round(6).tolist()
        [90.0]
    """
    return np.degrees(Rotation.from_matrix(np.swapaxes(a, 1, 2) @ b).magnitude())


def spread(values: np.ndarray) -> dict[str, float]:
    """Mean, median and max of `values` as floats.

    Example:
        >>> spread(np.array([1.0, 2.0, 6.0]))
        {'mean': 3.0, 'median': 2.0, 'max': 6.0}
    """
    return {"mean": float(np.mean(values)), "median": float(np.median(values)), "max": float(np.max(values))}


def relative_rotation_errors_deg(true_rot: np.ndarray, est_rot: np.ndarray) -> np.ndarray:
    """Over every pair i < j of (N, 3, 3) camera-to-world rotations: the angle between the true and the
    estimated rotation from view j's camera to view i's, degrees (empty for fewer than 2 views)."""
    i, j = np.triu_indices(len(true_rot), 1)
    true_rel = np.swapaxes(true_rot[i], 1, 2) @ true_rot[j]
    est_rel = np.swapaxes(est_rot[i], 1, 2) @ est_rot[j]
    return rotation_angles_deg(true_rel, est_rel) if len(i) else np.zeros(0)


def pose_errors(true_c2w: np.ndarray, est_c2w: np.ndarray, radius: float) -> dict[str, Any]:
    """Centre and rotation errors of the (N, 4, 4) estimated camera-to-world poses against the true ones,
    after the similarity fit of the estimated centres to the true (N >= 3, centres not collinear)."""
    fit = umeyama(est_c2w[:, :3, 3], true_c2w[:, :3, 3])
    centre_m = np.linalg.norm(fit.apply(est_c2w[:, :3, 3]) - true_c2w[:, :3, 3], axis=1)
    rotation = rotation_angles_deg(true_c2w[:, :3, :3], fit.rotation @ est_c2w[:, :3, :3])
    relative = relative_rotation_errors_deg(true_c2w[:, :3, :3], est_c2w[:, :3, :3])
    return {
        "views": len(true_c2w),
        "scale": fit.scale,
        "scan_radius_m": radius,
        "centre_error_cm": spread(centre_m * 100.0),
        "centre_error_pct_radius": spread(centre_m / radius * 100.0),
        "rotation_error_deg": spread(rotation),
        "relative_rotation_error_deg": {"median": float(np.median(relative)), "max": float(np.max(relative))},
    }


def model_poses(model: pycolmap.Reconstruction) -> dict[str, np.ndarray]:
    """Image name -> its 4x4 camera-to-world pose (OpenCV axes, COLMAP's world) for every registered image."""
    poses = {}
    for image in model.images.values():
        if image.has_pose:
            poses[image.name] = np.linalg.inv(np.vstack([image.cam_from_world().matrix(), [0, 0, 0, 1]]))
    return poses


def model_summary(model: pycolmap.Reconstruction) -> dict[str, Any]:
    """Registered images (count and names), 3D points, mean reprojection error (px), mean track length."""
    names = sorted(model_poses(model))
    return {"registered": len(names), "points": model.num_points3D(),
            "reprojection_error_px": float(model.compute_mean_reprojection_error()),
            "mean_track_length": float(model.compute_mean_track_length()), "images": names}


def sfm_report(models: tuple[pycolmap.Reconstruction, ...], truth: dict[str, np.ndarray],
               radius: float, world_frame: bool = False) -> dict[str, Any]:
    """The result of COLMAP on the views `truth` (name -> true camera-to-world): the largest model's
    registration, points and reprojection error, every model's summary, and the largest model's pose
    errors (None when fewer than 3 views, or only collinear centres, registered). `world_frame`: the
    model is in the world frame (position priors), so its centre errors without a fit are reported too."""
    summaries = [model_summary(m) for m in models]
    best = summaries[0] if summaries else {"registered": 0, "points": 0, "reprojection_error_px": None}
    report = {"views": len(truth), "registered": best["registered"],
              "registered_share": best["registered"] / len(truth) if truth else 0.0,
              "models": len(models), "registered_in_any_model": sum(s["registered"] for s in summaries),
              "points": best["points"], "reprojection_error_px": best["reprojection_error_px"],
              "pose_error": None, "model_summaries": summaries}
    if models:
        poses = model_poses(models[0])
        names = sorted(name for name in poses if name in truth)
        if len(names) >= 3:
            true, est = np.stack([truth[n] for n in names]), np.stack([poses[n] for n in names])
            if world_frame:
                report["centre_error_world_cm"] = spread(
                    np.linalg.norm(est[:, :3, 3] - true[:, :3, 3], axis=1) * 100.0)
            try:
                report["pose_error"] = pose_errors(true, est, radius)
            except ValueError as err:  # collinear centres: no unique fit, said in the report
                report["pose_error_note"] = str(err)
    return report
