"""View datasets on disk (docs/data-formats.md), readable by nerfstudio and Open3D users.

A dataset folder holds `transforms.json` (nerfstudio layout: OpenGL
camera-to-world `transform_matrix`, principal point with pixel centres at +0.5;
our own fields under the `nbv` key), `images/NNNN.png` (sRGB uint8) and
`depth/NNNN.png` (uint16 millimetres of z-depth, `depth_unit_scale_factor`
0.001, 0 for no hit). Writing is atomic: frames go to a hidden temporary folder
beside the target, renamed into place only when complete.
"""

from __future__ import annotations

import errno
import json
from collections.abc import Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from PIL import Image

from common.io import atomic_folder, check_output_folder, write_json, write_text
from common.io import current_umask as current_umask  # re-exported: dataset folders use the umask
from common.io import replace_folder as replace_folder  # re-exported for render.colmap
from render.camera import UAVCamera
from render.dataset_read import (
    DEPTH_SCALE,
    FORMAT_VERSION,
    DatasetError,
    check_shared_images,
    contained_file,
    object_field,
    read_camera,
    read_center,
    read_document,
    read_png,
    read_pose,
    read_render_settings,
    read_viewpoint,
    typed_field,
)
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, opencv_to_opengl, validate_pose

APPLIED_TRANSFORM = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]
"""nerfstudio's `applied_transform`, written explicitly as the identity (poses are stored as they are)."""


@dataclass(frozen=True)
class Frame:
    """One view of a dataset: file paths and pose."""

    rgb_path: Path
    """The sRGB PNG."""
    depth_path: Path | None
    """The uint16 millimetre depth PNG (None: a capture from another tool, which has no depth)."""
    c2w: np.ndarray
    """4x4 camera-to-world, OpenCV convention, float64."""
    viewpoint: Viewpoint | None = None
    """The spherical viewpoint it was planned at, when known."""
    meta: dict[str, Any] = field(default_factory=dict)
    """The frame's `nbv` fields (e.g. `source_index` in a refined dataset)."""


@dataclass(frozen=True)
class ViewDataset:
    """A dataset read from disk; images load lazily."""

    root: Path
    """The dataset folder."""
    camera: UAVCamera
    """Intrinsics and depth range shared by all frames."""
    frames: tuple[Frame, ...]
    """Frames in capture order."""
    meta: dict[str, Any]
    """The top-level `nbv` fields: scene, centre, render settings (`render_settings` parses them), seed,
    plan."""

    def __len__(self) -> int:
        return len(self.frames)

    @property
    def center(self) -> np.ndarray:
        """The scene centre the viewpoints are relative to."""
        return read_center(self.meta, self.root / "transforms.json")

    @property
    def render_settings(self) -> RenderSettings | None:
        """The render settings recorded in `nbv.render` (None when the writer recorded none)."""
        return read_render_settings(self.meta, self.root / "transforms.json")

    def poses(self) -> np.ndarray:
        """(N, 4, 4) camera-to-world matrices, OpenCV convention."""
        return np.stack([f.c2w for f in self.frames]) if self.frames else np.zeros((0, 4, 4))

    def rgb(self, index: int) -> np.ndarray:
        """Frame `index` as H x W x 3 uint8 sRGB."""
        return read_png(self.frames[index].rgb_path, self.camera.width, self.camera.height, depth=False)

    def depth(self, index: int) -> np.ndarray:
        """Frame `index` as H x W float32 z-depth in metres (0: no hit)."""
        raw = read_png(self.frames[index].depth_path, self.camera.width, self.camera.height, depth=True)
        return png_to_depth(raw)


def depth_to_png(depth: np.ndarray) -> np.ndarray:
    """Float metres to uint16 millimetres (rounded; values beyond 65.535 m clip to 0)."""
    mm = np.round(np.asarray(depth, dtype=np.float64) / DEPTH_SCALE)
    mm[(mm < 0) | (mm > np.iinfo(np.uint16).max) | ~np.isfinite(mm)] = 0
    return mm.astype(np.uint16)


def png_to_depth(raw: np.ndarray) -> np.ndarray:
    """A depth PNG's uint16 millimetres as H x W float32 metres (0: no hit)."""
    return raw.astype(np.float32) * np.float32(DEPTH_SCALE)


def stored_depth(depth: np.ndarray) -> np.ndarray:
    """A rendered depth map as a dataset stores and reads it back: rounded to whole millimetres."""
    return png_to_depth(depth_to_png(depth))


class DatasetWriter:
    """Writes a dataset atomically: use as a context manager, `add` frames, leave the block.

    Leaving the block normally renames the temporary folder onto `out`; an
    exception (or Ctrl-C) removes it, and whatever stood at `out` before is kept.
    Extra files written into `folder` inside the block are part of the same swap.
    """

    def __init__(self, out: str | Path, camera: UAVCamera, meta: dict[str, Any],
                 overwrite: bool = False) -> None:
        self.out = Path(out)
        self.camera = camera
        self.meta = dict(meta)
        self.overwrite = overwrite
        self._frames: list[dict[str, Any]] = []
        self._tmp: Path | None = None
        self._stack = ExitStack()
        check_output_folder(self.out, overwrite)

    @property
    def folder(self) -> Path:
        """The temporary folder being written (inside the with-block)."""
        assert self._tmp is not None, "DatasetWriter.folder used outside its with-block"
        return self._tmp

    def __enter__(self) -> DatasetWriter:
        self._tmp = self._stack.enter_context(atomic_folder(self.out, self.overwrite))
        (self._tmp / "images").mkdir()
        (self._tmp / "depth").mkdir()
        return self

    def add(self, rgb: np.ndarray, depth: np.ndarray, c2w: np.ndarray,
            viewpoint: Viewpoint | None = None, meta: dict[str, Any] | None = None) -> None:
        """Append one frame; shapes must match the camera."""
        assert self._tmp is not None, "DatasetWriter.add called outside its with-block"
        h, w = self.camera.height, self.camera.width
        if rgb.shape != (h, w, 3) or rgb.dtype != np.uint8:
            raise ValueError(f"rgb must be ({h}, {w}, 3) uint8, got {rgb.shape} {rgb.dtype}")
        if depth.shape != (h, w):
            raise ValueError(f"depth must be ({h}, {w}), got {depth.shape}")
        pose = validate_pose(c2w, f"frame {len(self._frames)} pose")
        name = f"{len(self._frames):04d}.png"
        Image.fromarray(rgb).save(self._tmp / "images" / name)
        depth_file = self._tmp / "depth" / name
        if not cv2.imwrite(str(depth_file), depth_to_png(depth)):  # cv2 returns False, never raises
            raise OSError(errno.EIO, "the depth image could not be written", str(depth_file))
        frame_meta = dict(meta or {})
        if viewpoint is not None:
            frame_meta["viewpoint"] = viewpoint.as_array().tolist()
        self._frames.append({
            "file_path": f"images/{name}",
            "depth_file_path": f"depth/{name}",
            "transform_matrix": opencv_to_opengl(pose).tolist(),
            "nbv": frame_meta,
        })

    def __exit__(self, exc_type, exc, tb) -> None:
        assert self._tmp is not None
        if exc_type is not None:
            self._stack.__exit__(exc_type, exc, tb)
            return
        with self._stack:
            if not self._frames:
                raise ValueError(f"dataset {self.out}: no frames were added "
                                 "(a dataset needs at least one view)")
            write_strict_json(self._tmp / "transforms.json",
                              transforms_json(self.camera, self._frames, self.meta))


def write_strict_json(path: Path, doc: dict[str, Any]) -> None:
    """Write `doc` as indented JSON that strict readers (JavaScript, serde, Go) accept: a NaN or infinity
    is a ValueError naming `path`, never a bare `NaN` token."""
    try:
        text = json.dumps(doc, indent=2, allow_nan=False)
    except ValueError as err:
        raise ValueError(f"{path}: cannot write a NaN or infinite number as JSON ({err})") from err
    write_text(path, text)


def transforms_json(camera: UAVCamera, frames: list[dict[str, Any]], meta: dict[str, Any]) -> dict:
    """The nerfstudio-layout document (principal point shifted +0.5 px to its convention)."""
    k = camera.K
    return {
        "camera_model": "OPENCV",
        "fl_x": k[0, 0], "fl_y": k[1, 1],
        "cx": k[0, 2] + 0.5, "cy": k[1, 2] + 0.5,
        "w": camera.width, "h": camera.height,
        "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0,
        "depth_unit_scale_factor": DEPTH_SCALE,
        "applied_transform": APPLIED_TRANSFORM,
        "frames": frames,
        "nbv": {"version": FORMAT_VERSION, "focal_mm": camera.focal_mm, "near_m": camera.near_m,
                "far_m": camera.far_m, **meta},
    }


def read_dataset(path: str | Path) -> ViewDataset:
    """Read and validate a dataset folder; errors name the file and the field at fault."""
    root = Path(path)
    doc_path = root / "transforms.json"
    doc = read_document(doc_path)
    _check_applied_transform(doc, doc_path)
    nbv = object_field(doc, "nbv", doc_path)
    camera = read_camera(doc, nbv, doc_path)
    center = read_center(nbv, doc_path)
    read_render_settings(nbv, doc_path)
    raw_frames = typed_field(doc, "frames", list, doc_path)
    if not raw_frames:
        raise DatasetError(f"{doc_path}: field frames is empty (a dataset needs at least one view)")
    frames = tuple(_read_frame(root, i, f, center, doc_path) for i, f in enumerate(raw_frames))
    check_shared_images(((str(f.rgb_path), str(f.depth_path), f.c2w) for f in frames), doc_path)
    return ViewDataset(root, camera, frames, dict(nbv))


def _check_applied_transform(doc: dict, where: Path) -> None:
    """Accept an absent (files written before it) or identity 3x4 `applied_transform`; refuse others."""
    if "applied_transform" not in doc:
        return
    try:
        matrix = np.asarray(doc["applied_transform"], dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        matrix = None
    if matrix is None or matrix.shape != (3, 4) or not np.allclose(matrix, APPLIED_TRANSFORM, atol=1e-9):
        raise DatasetError(f"{where}: field applied_transform must be the 3x4 identity (poses are read as "
                           f"stored), got {doc['applied_transform']!r}")


def _read_frame(root: Path, i: int, frame: Any, center: np.ndarray, where: Path) -> Frame:
    prefix = f"frames[{i}]."
    if not isinstance(frame, dict):
        raise DatasetError(f"{where}: frames[{i}] must be an object")
    rgb, depth = (contained_file(root, typed_field(frame, key, str, where, prefix), where, prefix + key)
                  for key in ("file_path", "depth_file_path"))
    c2w = read_pose(frame, where, prefix)
    meta = object_field(frame, "nbv", where, prefix)
    source = meta.get("source_index", 0)
    if isinstance(source, bool) or not isinstance(source, int) or source < 0:
        raise DatasetError(f"{where}: field {prefix}nbv.source_index must be a non-negative integer")
    return Frame(rgb, depth, c2w, read_viewpoint(meta, c2w, center, where, prefix), dict(meta))


def iter_views(dataset: ViewDataset) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(rgb, depth, c2w) for every frame, in order."""
    for i, frame in enumerate(dataset.frames):
        yield dataset.rgb(i), dataset.depth(i), frame.c2w


def write_subset(dataset: ViewDataset, indices: list[int], out: str | Path,
                 meta: dict[str, Any], overwrite: bool = False, extra: dict[str, Any] | None = None) -> None:
    """Write the frames `indices` of `dataset` as a new dataset (frames record `source_index`).

    `extra`: JSON documents by file name, written into the dataset folder in the same atomic swap."""
    merged = {**dataset.meta, **meta}
    with DatasetWriter(out, dataset.camera, merged, overwrite) as writer:
        for name, doc in (extra or {}).items():
            write_json(writer.folder / name, doc)
        for i in indices:
            frame = dataset.frames[i]
            writer.add(dataset.rgb(i), dataset.depth(i), frame.c2w, frame.viewpoint,
                       {**frame.meta, "source_index": int(i)})
