"""A capture's images: JPEG or PNG decoded under the strict reader's checks, undistorted to a pinhole.

Distortion is handled by undistorting the images (not the keypoints): each frame is resampled
(bilinear, `cv2.undistort`) onto the pinhole camera with its own fx, fy, cx, cy and no distortion, so
SIFT sees straight lines straight. A frame without distortion is passed through untouched.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from render.dataset_read import MAX_PIXELS, MAX_SIDE, DatasetError, image_bytes, read_png

_PNG = b"\x89PNG\r\n\x1a\n"
_JPEG = b"\xff\xd8\xff"


@dataclass(frozen=True)
class Intrinsics:
    """One frame's camera: size, pinhole K in OpenCV pixels (centres at integers), OpenCV distortion."""

    width: int
    """Image width, pixels."""
    height: int
    """Image height, pixels."""
    fx: float
    """Horizontal focal length, pixels."""
    fy: float
    """Vertical focal length, pixels."""
    cx: float
    """Principal point x, OpenCV convention (a tool's +0.5-centred cx minus 0.5)."""
    cy: float
    """Principal point y, OpenCV convention."""
    distortion: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)
    """OpenCV coefficients (k1, k2, p1, p2[, k3[, k4, k5, k6]])."""

    @property
    def K(self) -> np.ndarray:  # noqa: N802 - the usual name of the intrinsic matrix
        """3x3 intrinsic matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def tag(self) -> list[float]:
        """What the undistorted image depends on besides the file (keys the feature cache)."""
        return [self.fx, self.fy, self.cx, self.cy, *self.distortion] if any(self.distortion) else []

    def undistort(self, image: np.ndarray) -> np.ndarray:
        """`image` resampled onto the distortion-free camera of the same K (unchanged without distortion)."""
        if not any(self.distortion):
            return image
        return cv2.undistort(image, self.K, np.array(self.distortion), newCameraMatrix=self.K)


def check_intrinsics(intr: Intrinsics, where: Path, name: str) -> Intrinsics:
    """`intr` when its size and focal lengths are in range and every number is finite; else a
    `DatasetError` naming `where` and the camera `name`."""
    for key, size in (("width", intr.width), ("height", intr.height)):
        if not 1 <= size <= MAX_SIDE:
            raise DatasetError(f"{where}: {name} {key} must lie in [1, {MAX_SIDE}], got {size}")
    if intr.width * intr.height > MAX_PIXELS:
        raise DatasetError(f"{where}: {name} has {intr.width * intr.height} pixels, more than {MAX_PIXELS}")
    values = (intr.fx, intr.fy, intr.cx, intr.cy, *intr.distortion)
    if not all(math.isfinite(v) for v in values):
        raise DatasetError(f"{where}: {name} has NaN or infinite intrinsics {values}")
    if intr.fx <= 0 or intr.fy <= 0:
        raise DatasetError(f"{where}: {name} focal lengths must be positive, got {intr.fx:g}, {intr.fy:g}")
    if any(abs(v) > 10 for v in intr.distortion):
        raise DatasetError(f"{where}: {name} distortion {intr.distortion} is beyond |10| (not a lens)")
    return intr


def read_image(path: Path, width: int, height: int) -> np.ndarray:
    """The JPEG or PNG at `path` as H x W x 3 uint8 RGB, checked to be `width` x `height`."""
    data = image_bytes(path, width, height)
    if data.startswith(_PNG):
        return read_png(path, width, height, depth=False)
    if not data.startswith(_JPEG):
        raise DatasetError(f"{path}: not a JPEG or PNG image")
    try:
        with Image.open(io.BytesIO(data)) as img:
            size = img.size
            image = np.asarray(img.convert("RGB")) if size == (width, height) else None
    except (OSError, ValueError, SyntaxError, Image.DecompressionBombError) as err:
        raise DatasetError(f"{path}: cannot decode JPEG: {err}") from err
    if image is None:
        raise DatasetError(f"{path}: image is {size[0]}x{size[1]}, its camera says {width}x{height}")
    return image
