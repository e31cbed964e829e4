"""Spherical viewpoints (paper Sec. IV's {R, phi, theta}) and camera poses.

A viewpoint is (radius R, azimuth phi in [0, 2pi), elevation theta above the
horizon) about the scene centre; the camera sits there and looks at the
centre. Poses are 4x4 camera-to-world matrices in the OpenCV convention
(x right, y down, z forward), float64.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Viewpoint:
    """A camera position on a sphere about the scene centre, looking at the centre."""

    radius: float
    """Distance from the scene centre, metres."""
    azimuth: float
    """Counter-clockwise from +x about +z, radians, wrapped to [0, 2pi)."""
    elevation: float
    """Above the horizontal plane through the centre, radians, in [-pi/2, pi/2]."""

    def __post_init__(self) -> None:
        values = (self.radius, self.azimuth, self.elevation)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"viewpoint has NaN or infinite values: {values}")
        if self.radius <= 0:
            raise ValueError(f"viewpoint radius must be positive, got {self.radius}")
        if abs(self.elevation) > math.pi / 2 + 1e-9:
            raise ValueError(f"viewpoint elevation must lie in [-pi/2, pi/2], got {self.elevation}")
        object.__setattr__(self, "azimuth", self.azimuth % TWO_PI)

    def as_array(self) -> np.ndarray:
        """(R, azimuth, elevation) as float64."""
        return np.array([self.radius, self.azimuth, self.elevation])


def draw_viewpoint(low: np.ndarray, high: np.ndarray, rng: np.random.Generator) -> Viewpoint:
    """A viewpoint uniform between `low` and `high` (R, azimuth, elevation): one `rng.random(3)` draw.

    Example:
        >>> draw_viewpoint(np.array([1.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.5]), np.random.default_rng(0))
        Viewpoint(radius=1.6369616873214543, azimuth=0.2697867137638703, elevation=0.020486761968097345)
    """
    return Viewpoint(*map(float, low + rng.random(3) * (high - low)))


def viewpoint_to_c2w(view: Viewpoint, center: np.ndarray) -> np.ndarray:
    """Camera-to-world (OpenCV) of a camera at `view` looking at `center`.

    The camera's x axis stays horizontal, so the pose is defined at the poles too.
    """
    ce, se = math.cos(view.elevation), math.sin(view.elevation)
    ca, sa = math.cos(view.azimuth), math.sin(view.azimuth)
    outward = np.array([ce * ca, ce * sa, se])
    forward = -outward
    right = np.array([-sa, ca, 0.0])
    down = np.cross(forward, right)
    c2w = np.eye(4)
    c2w[:3, 0], c2w[:3, 1], c2w[:3, 2] = right, down, forward
    c2w[:3, 3] = np.asarray(center, dtype=np.float64) + view.radius * outward
    return c2w


def c2w_to_viewpoint(c2w: np.ndarray, center: np.ndarray) -> Viewpoint:
    """The spherical viewpoint of a camera position (its orientation is not used)."""
    validate_pose(c2w)
    offset = c2w[:3, 3] - np.asarray(center, dtype=np.float64)
    radius = float(np.linalg.norm(offset))
    elevation = math.asin(max(-1.0, min(1.0, offset[2] / radius)))
    azimuth = math.atan2(offset[1], offset[0])
    return Viewpoint(radius, azimuth, elevation)


def validate_pose(c2w: np.ndarray, name: str = "pose") -> np.ndarray:
    """Check a 4x4 rigid camera-to-world matrix; return it as float64 or raise naming the fault."""
    pose = np.asarray(c2w, dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"{name} must be 4x4, got shape {pose.shape}")
    if not np.all(np.isfinite(pose)):
        raise ValueError(f"{name} contains NaN or infinite values")
    rot = pose[:3, :3]
    if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-5) or np.linalg.det(rot) < 0:
        raise ValueError(f"{name} rotation is not a proper rotation matrix")
    if not np.allclose(pose[3], [0, 0, 0, 1]):
        raise ValueError(f"{name} last row must be [0, 0, 0, 1], got {pose[3]}")
    return pose


OPENCV_TO_OPENGL = np.diag([1.0, -1.0, -1.0, 1.0])
"""Right-multiply a camera-to-world to swap OpenCV (y down, z forward) and OpenGL axes."""


def opencv_to_opengl(c2w: np.ndarray) -> np.ndarray:
    """OpenCV camera-to-world to OpenGL (nerfstudio) camera-to-world, and back (an involution)."""
    return np.asarray(c2w, dtype=np.float64) @ OPENCV_TO_OPENGL
