"""The paper's UAV Camera (Sec. V-A): a pinhole with a 36 x 24 mm sensor.

Pixels are square and the sensor width is fitted to the image width (Blender's
"auto" sensor fit, as the View Planning Toolbox used): fx = fy = f_mm * W / 36.
In memory K follows OpenCV, pixel centres at integer coordinates, so the
principal point of a centred sensor is ((W - 1) / 2, (H - 1) / 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SENSOR_WIDTH_MM = 36.0
SENSOR_HEIGHT_MM = 24.0
FOCAL_RANGE_MM = (1.0, 10_000.0)
"""Focal lengths accepted: a 1 mm lens sees 172 degrees across, a 10 m one 0.2 degrees."""


@dataclass(frozen=True)
class UAVCamera:
    """Intrinsics and depth range of the simulated UAV camera."""

    width: int = 320
    """Image width in pixels."""
    height: int = 240
    """Image height in pixels."""
    focal_mm: float = 35.0
    """Focal length in millimetres on the 36 mm wide sensor, in [1, 10000]."""
    near_m: float = 0.05
    """Nearest depth reported, metres."""
    far_m: float = 10.0
    """Farthest depth reported, metres; beyond it depth is 0."""

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or value <= 0:
                raise ValueError(f"camera {name} must be a positive integer, got {value!r}")
        for name in ("focal_mm", "near_m", "far_m"):
            value = getattr(self, name)
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"camera {name} must be positive and finite, got {value!r}")
        if not FOCAL_RANGE_MM[0] <= self.focal_mm <= FOCAL_RANGE_MM[1]:
            raise ValueError(f"camera focal_mm must lie in [{FOCAL_RANGE_MM[0]:g}, {FOCAL_RANGE_MM[1]:g}], "
                             f"got {self.focal_mm!r}")
        if self.near_m >= self.far_m:
            raise ValueError(f"camera near_m ({self.near_m}) must be below far_m ({self.far_m})")

    @property
    def fx(self) -> float:
        """Focal length in pixels (square pixels: fx = fy)."""
        return self.focal_mm * self.width / SENSOR_WIDTH_MM

    @property
    def fov_x_deg(self) -> float:
        """Horizontal field of view in degrees."""
        return math.degrees(2.0 * math.atan(SENSOR_WIDTH_MM / (2.0 * self.focal_mm)))

    @property
    def fov_y_deg(self) -> float:
        """Vertical field of view in degrees."""
        return math.degrees(2.0 * math.atan((self.height / 2.0) / self.fx))

    @property
    def K(self) -> np.ndarray:  # noqa: N802 - the standard name
        """3x3 float64 intrinsics, OpenCV convention (pixel centres at integers)."""
        return np.array(
            [
                [self.fx, 0.0, (self.width - 1) / 2.0],
                [0.0, self.fx, (self.height - 1) / 2.0],
                [0.0, 0.0, 1.0],
            ]
        )

    def with_resolution(self, width: int, height: int) -> UAVCamera:
        """The same lens at another resolution (the field of view is kept)."""
        return UAVCamera(width, height, self.focal_mm, self.near_m, self.far_m)


def pixel_rays(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W, 3) camera-frame directions through each pixel centre, z = 1 (so a hit's t is its z-depth).

    Example:
        >>> rays = pixel_rays(UAVCamera(4, 2).K, 4, 2)
        >>> rays.shape, rays[0, 0, 2], bool(rays[0, 0, 0] < 0 < rays[0, 3, 0])
        ((2, 4, 3), np.float64(1.0), True)
    """
    k = np.asarray(K, dtype=np.float64)
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    return np.stack([(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1], np.ones(u.shape)], -1)
