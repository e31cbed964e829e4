"""Motion blur as Mitsuba 3.9 lacks it: the mean of renders at sub-frame poses within the exposure.

The camera is taken to move sideways, along its own x axis (right, OpenCV),
as it does when flying a scan ring, by `travel_m` metres while the shutter is
open, and to keep its orientation (over a few centimetres the turn towards the
scene centre is negligible). Sub-frames sit at the centres of `frames` equal
slices of the exposure, so their mean is centred on the view's pose.
"""

from __future__ import annotations

import numpy as np


def subframe_poses(c2w: np.ndarray, travel_m: float, frames: int) -> list[np.ndarray]:
    """Camera-to-world poses (OpenCV) of the sub-frames of one exposure; `[c2w]` when `travel_m` is 0.

    Example:
        >>> [round(float(p[0, 3]), 3) for p in subframe_poses(np.eye(4), 0.4, 4)]
        [-0.15, -0.05, 0.05, 0.15]
    """
    if travel_m == 0.0:
        return [c2w]
    poses = []
    for k in range(frames):
        pose = np.array(c2w, dtype=np.float64)
        pose[:3, 3] += ((k + 0.5) / frames - 0.5) * travel_m * pose[:3, 0]
        poses.append(pose)
    return poses
