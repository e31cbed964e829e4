"""A capture from another tool as a view dataset: its frames in the estimated target frame, no depth.

`CaptureDataset` is a `ViewDataset` whose poses are local (target centre at the origin, up +z,
azimuth 0 at the first frame, median camera distance 1), whose viewpoints are those poses', whose
images are undistorted on reading (`render.captures.images`) and which has no depth. What writing
the kept frames back needs (the COLMAP model, the transforms.json document) rides along in `source`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from render.camera import SENSOR_WIDTH_MM, UAVCamera
from render.captures.frame import CaptureFrameConfig, TargetFrame, local_viewpoint, target_frame
from render.captures.images import Intrinsics, read_image
from render.dataset import Frame, ViewDataset
from render.dataset_read import DatasetError


@dataclass(frozen=True)
class CaptureDataset(ViewDataset):
    """A COLMAP or nerfstudio capture, read for refinement: local poses, undistorted images, no depth."""

    kind: str
    """"colmap" or "nerfstudio": the format it was read from and is written back in."""
    intrinsics: tuple[Intrinsics, ...]
    """Each frame's camera as the capture gives it."""
    keys: tuple[Any, ...]
    """Each frame's record in `source`: a COLMAP image id, or an index into transforms.json's frames."""
    source: Any
    """What writing back needs: (COLMAP model, images folder) or the transforms.json document."""
    target: TargetFrame
    """The target frame the local poses are expressed in (world coordinates of the capture)."""

    def rgb(self, index: int) -> np.ndarray:
        """Frame `index` as H x W x 3 uint8 RGB, undistorted onto its pinhole camera."""
        intr = self.intrinsics[index]
        return intr.undistort(read_image(self.frames[index].rgb_path, intr.width, intr.height))

    def depth(self, index: int) -> np.ndarray:
        """Never: a capture from another tool has no depth maps."""
        raise DatasetError(no_depth_message(self.root, self.kind))


def no_depth_message(root: Path, kind: str) -> str:
    """The error for a command that needs depth given a capture of format `kind`."""
    name = "a COLMAP model" if kind == "colmap" else "a nerfstudio transforms.json capture"
    return (f"{root}: {name} has no depth maps, and this command needs depth (TSDF fusion fuses depth); "
            f"only a dataset from `nbv scan` carries it. `nbv refine` works on captures; mesh a capture "
            f"with COLMAP or nerfstudio and pass the mesh file to `nbv evaluate`")


def build_capture(root: Path, kind: str, where: Path, views: list[tuple[Path, np.ndarray, Intrinsics]],
                  keys: list[Any], source: Any, config: CaptureFrameConfig) -> CaptureDataset:
    """The capture of `views` (image path, world OpenCV camera-to-world, intrinsics), in capture order."""
    if not views:
        raise DatasetError(f"{where}: the capture has no frames")
    sizes = {(intr.width, intr.height) for _, _, intr in views}
    if len(sizes) > 1:
        listed = ", ".join(f"{w}x{h}" for w, h in sorted(sizes))
        raise DatasetError(f"{where}: frames differ in image size ({listed}); refinement needs one size")
    target = target_frame(np.stack([c2w for _, c2w, _ in views]), config, where)
    frames = []
    for path, c2w, intr in views:
        local = target.to_local(c2w)
        meta = {"undistort": intr.tag()} if intr.tag() else {}
        frames.append(Frame(path, None, local, local_viewpoint(local), meta))
    first = views[0][2]
    try:
        camera = UAVCamera(first.width, first.height, first.fx * SENSOR_WIDTH_MM / first.width)
    except ValueError as err:
        raise DatasetError(f"{where}: frame 0's camera: {err}") from err
    meta = {"center": [0.0, 0.0, 0.0], "capture": {"format": kind, **target.record()}}
    return CaptureDataset(root, camera, tuple(frames), meta, kind, tuple(v[2] for v in views), tuple(keys),
                          source, target)
