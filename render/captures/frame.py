"""The target frame of a capture from another tool: centre, up axis and azimuth origin from its cameras.

A capture (COLMAP, nerfstudio, a phone app) comes in a world frame and scale of its own. The Bag of
Views needs each view's azimuth about the target. The target centre is estimated as the point nearest
all optical axes (least squares), the up axis as the normal of the plane the cameras' x axes lie in
(a level camera's x axis is horizontal; measured on a 288-view hemisphere scan this is exact where
the cameras' mean up vector, which also orients it, tilts 0.26 degrees), and azimuth 0 is the first
frame's direction from the centre (counter-clockwise about up, as in DESIGN.md §2). Each is
carried along by a rotation, translation and scale of the world, so the azimuths, and so the kept
views, do not depend on the frame's gauge. Either estimate can be given instead (`CaptureFrameConfig`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from render.dataset_read import DatasetError
from render.viewpoint import TWO_PI, Viewpoint

MIN_AXIS_SPREAD = 0.01
"""Smallest eigenvalue of the mean (I - d d^T) over the optical axes d for the centre to be estimated
(0: all axes parallel, as in a forward-facing capture)."""
MIN_UP_AGREEMENT = 0.1
"""Smallest length of the mean of the cameras' unit up vectors for it to define an up axis."""
LEVEL_SPREAD = 0.05
"""The x axes define the up axis when the scatter of the cameras' x axes has its smallest eigenvalue
below this (they lie near one plane: ~13 degrees of roll RMS) and its middle one above it (they span
that plane, as they do when the cameras face different ways); else the mean up vector does."""
AZIMUTH_GRID = 1e-9
"""Azimuths are rounded up onto this grid (rad), so a view on a range boundary (within float noise,
~1e-15 rad) falls in the range above it, as its exact azimuth does, in every gauge."""


@dataclass(frozen=True)
class CaptureFrameConfig:
    """The target frame of a capture from another tool (COLMAP, nerfstudio): estimated unless given."""

    capture_center: tuple[float, float, float] | None = None
    """Target centre of a COLMAP or nerfstudio capture, in its world coordinates (default: the point
    nearest all optical axes, printed)."""
    capture_up: tuple[float, float, float] | None = None
    """Up direction of a COLMAP or nerfstudio capture, in its world coordinates (default: the cameras'
    mean up vector, printed)."""

    def __post_init__(self) -> None:
        for name in ("capture_center", "capture_up"):
            value = getattr(self, name)
            if value is not None and not all(math.isfinite(v) for v in value):
                raise ValueError(f"{name} must be three finite numbers, got {value}")
        if self.capture_up is not None and not any(self.capture_up):
            raise ValueError("capture_up must not be the zero vector")


@dataclass(frozen=True)
class TargetFrame:
    """A capture's target frame: where the target is, which way is up, where azimuth 0 lies."""

    center: np.ndarray
    """Target centre, world coordinates."""
    up: np.ndarray
    """Unit up vector, world coordinates."""
    east: np.ndarray
    """Unit horizontal direction of azimuth 0 (towards the first frame's camera), world coordinates."""
    scale: float
    """1 / the median camera distance to the centre: local coordinates are in those units."""
    estimated: tuple[bool, bool]
    """Whether the centre and the up vector were estimated (else given)."""
    axis_miss: float
    """RMS distance of the optical axes from the centre, over the median camera distance."""

    def basis(self) -> np.ndarray:
        """3x3 rotation whose rows are the local x (azimuth 0), y and z (up) axes in world coordinates."""
        return np.stack([self.east, np.cross(self.up, self.east), self.up])

    def to_local(self, c2w: np.ndarray) -> np.ndarray:
        """A world camera-to-world as a local one: centre at the origin, up +z, azimuth 0 along +x."""
        local = np.eye(4)
        local[:3, :3] = self.basis() @ c2w[:3, :3]
        local[:3, 3] = self.basis() @ (c2w[:3, 3] - self.center) * self.scale
        return local

    def record(self) -> dict[str, Any]:
        """The frame as JSON: centre, up, azimuth-0 direction, whether estimated, the axes' miss."""
        return {"center": self.center.tolist(), "up": self.up.tolist(), "azimuth_zero": self.east.tolist(),
                "center_estimated": self.estimated[0], "up_estimated": self.estimated[1],
                "axis_miss": round(self.axis_miss, 6)}


def nearest_point_to_axes(origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, float]:
    """The point minimising the summed squared distance to the lines (origin, unit direction), and the
    smallest eigenvalue of the mean normal matrix (near 0: the lines are nearly parallel)."""
    projectors = np.eye(3) - directions[:, :, None] * directions[:, None, :]
    a, b = projectors.sum(0), np.einsum("nij,nj->i", projectors, origins)
    spread = float(np.linalg.eigvalsh(a / len(origins))[0])
    return np.linalg.lstsq(a, b, rcond=None)[0], spread


def target_frame(c2ws: np.ndarray, config: CaptureFrameConfig, where: Path) -> TargetFrame:
    """The target frame of cameras `c2ws` (N, 4, 4 OpenCV camera-to-world); a `DatasetError` naming
    `where` and the flag to give when an estimate is not defined."""
    origins, forwards = c2ws[:, :3, 3], c2ws[:, :3, 2]
    center, spread = np.asarray(config.capture_center, float), 1.0
    if config.capture_center is None:
        center, spread = nearest_point_to_axes(origins, forwards)
        if spread < MIN_AXIS_SPREAD or not np.all(np.isfinite(center)):
            raise DatasetError(f"{where}: the optical axes are nearly parallel (spread {spread:.2g}), so no "
                               f"target centre can be estimated; give --capture-center X Y Z")
        if np.mean(np.einsum("ni,ni->n", center - origins, forwards) > 0) < 0.5:
            raise DatasetError(f"{where}: the optical axes meet behind most cameras (not a capture around a "
                               f"target?); give --capture-center X Y Z")
    up = _up_vector(c2ws, config, where)
    offsets = origins - center
    distance = np.linalg.norm(offsets, axis=1)
    if np.min(distance) <= 1e-9 * max(1.0, float(np.max(distance))):
        raise DatasetError(f"{where}: frame {int(np.argmin(distance))}'s camera sits at the target centre; "
                           f"give --capture-center X Y Z")
    scale = 1.0 / float(np.median(distance))
    miss = np.linalg.norm(np.cross(center - origins, forwards), axis=1)
    return TargetFrame(center, up, _azimuth_zero(offsets, up, where), scale,
                       (config.capture_center is None, config.capture_up is None),
                       float(np.sqrt(np.mean(miss**2)) * scale))


def _up_vector(c2ws: np.ndarray, config: CaptureFrameConfig, where: Path) -> np.ndarray:
    """The given up vector, else the normal of the level cameras' x axes, else the cameras' mean up
    (minus the OpenCV image-down axis), which orients the normal; unit length."""
    if config.capture_up is not None:
        up = np.asarray(config.capture_up, float)
        return up / np.linalg.norm(up)
    mean = -c2ws[:, :3, 1].mean(0)
    if np.linalg.norm(mean) < MIN_UP_AGREEMENT:
        raise DatasetError(f"{where}: the cameras' up vectors disagree (mean length "
                           f"{np.linalg.norm(mean):.2g}), so no up axis is defined; give --capture-up X Y Z")
    right = c2ws[:, :3, 0]
    spread, axes = np.linalg.eigh(right.T @ right / len(right))
    if spread[0] < LEVEL_SPREAD < spread[1]:
        return axes[:, 0] * np.sign(axes[:, 0] @ mean)
    return mean / np.linalg.norm(mean)


def _azimuth_zero(offsets: np.ndarray, up: np.ndarray, where: Path) -> np.ndarray:
    """The horizontal direction of the first frame whose camera is off the vertical through the centre."""
    horizontal = offsets - np.outer(offsets @ up, up)
    lengths = np.linalg.norm(horizontal, axis=1)
    off_axis = np.flatnonzero(lengths > 1e-6 * np.linalg.norm(offsets, axis=1))
    if len(off_axis) == 0:
        raise DatasetError(f"{where}: every camera lies on the vertical through the target centre, so "
                           f"azimuths are undefined; give --capture-up X Y Z")
    return horizontal[off_axis[0]] / lengths[off_axis[0]]


def local_viewpoint(local_c2w: np.ndarray) -> Viewpoint:
    """The viewpoint of a local camera about the origin, its azimuth rounded up (`AZIMUTH_GRID`); a camera
    right above (or below) the centre takes the azimuth its x axis has on the sphere (x = (-sin a, cos a,
    0), as `render.viewpoint.viewpoint_to_c2w` poses it), since its position has none."""
    x, y, z = local_c2w[:3, 3]
    radius = math.sqrt(x * x + y * y + z * z)
    if math.hypot(x, y) > 1e-6 * radius:
        azimuth = math.atan2(y, x)
    else:
        azimuth = math.atan2(-local_c2w[0, 0], local_c2w[1, 0])
    azimuth = math.ceil(azimuth / AZIMUTH_GRID - 1e-3) * AZIMUTH_GRID % TWO_PI
    return Viewpoint(radius, azimuth, math.asin(max(-1.0, min(1.0, z / radius))))


def describe_frame(record: dict[str, Any]) -> str:
    """One line for the user: a capture's target centre and up axis, estimated or given (`record`: a
    `TargetFrame.record()` with the capture's `format`)."""
    def vector(values: list[float]) -> str:
        return "(" + ", ".join(f"{v:.4g}" for v in values) + ")"

    how = {True: "estimated", False: "given"}
    return (f"{record['format']} capture: target centre {vector(record['center'])} "
            f"{how[record['center_estimated']]} (optical axes miss it by {100 * record['axis_miss']:.2g} % "
            f"of the camera distance), up {vector(record['up'])} {how[record['up_estimated']]}; "
            f"override with --capture-center X Y Z, --capture-up X Y Z")
