"""View datasets on disk (docs/data-formats.md), readable by nerfstudio and Open3D users.

A dataset folder holds `transforms.json` (nerfstudio layout: OpenGL
camera-to-world `transform_matrix`, principal point with pixel centres at +0.5;
our own fields under the `nbv` key), `images/NNNN.png` (sRGB uint8) and
`depth/NNNN.png` (uint16 millimetres of z-depth, `depth_unit_scale_factor`
0.001, 0 for no hit). Writing is atomic: frames go to a hidden temporary folder
beside the target, renamed into place only when complete.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from PIL import Image

from common.io import write_json
from render.camera import UAVCamera
from render.viewpoint import Viewpoint, opencv_to_opengl, validate_pose

DEPTH_SCALE = 0.001
"""Metres per unit of the uint16 depth PNGs."""
FORMAT_VERSION = 1


class DatasetError(ValueError):
    """A dataset on disk is missing, corrupt or inconsistent; the message names the file and field."""


@dataclass(frozen=True)
class Frame:
    """One view of a dataset: file paths and pose."""

    rgb_path: Path
    """The sRGB PNG."""
    depth_path: Path
    """The uint16 millimetre depth PNG."""
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
    """The top-level `nbv` fields: scene, centre, render settings, seed, plan."""

    def __len__(self) -> int:
        return len(self.frames)

    @property
    def center(self) -> np.ndarray:
        """The scene centre the viewpoints are relative to."""
        return np.asarray(self.meta.get("center", [0.0, 0.0, 0.0]), dtype=np.float64)

    def poses(self) -> np.ndarray:
        """(N, 4, 4) camera-to-world matrices, OpenCV convention."""
        return np.stack([f.c2w for f in self.frames]) if self.frames else np.zeros((0, 4, 4))

    def rgb(self, index: int) -> np.ndarray:
        """Frame `index` as H x W x 3 uint8 sRGB."""
        path = self.frames[index].rgb_path
        try:
            with Image.open(path) as img:
                rgb = np.asarray(img.convert("RGB"))
        except (OSError, ValueError) as err:
            raise DatasetError(f"{path}: cannot read image: {err}") from err
        self._check_shape(path, rgb.shape[:2])
        return rgb

    def depth(self, index: int) -> np.ndarray:
        """Frame `index` as H x W float32 z-depth in metres (0: no hit)."""
        path = self.frames[index].depth_path
        raw = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if raw is None:
            raise DatasetError(f"{path}: cannot read depth image")
        if raw.dtype != np.uint16 or raw.ndim != 2:
            raise DatasetError(f"{path}: depth must be single-channel uint16, got {raw.dtype} {raw.shape}")
        self._check_shape(path, raw.shape)
        return raw.astype(np.float32) * np.float32(DEPTH_SCALE)

    def _check_shape(self, path: Path, shape: tuple[int, ...]) -> None:
        expected = (self.camera.height, self.camera.width)
        if tuple(shape) != expected:
            raise DatasetError(f"{path}: image is {shape[1]}x{shape[0]}, transforms.json says "
                               f"w={expected[1]}, h={expected[0]}")


def depth_to_png(depth: np.ndarray) -> np.ndarray:
    """Float metres to uint16 millimetres (rounded; values beyond 65.535 m clip to 0)."""
    mm = np.round(np.asarray(depth, dtype=np.float64) / DEPTH_SCALE)
    mm[(mm < 0) | (mm > np.iinfo(np.uint16).max) | ~np.isfinite(mm)] = 0
    return mm.astype(np.uint16)


class DatasetWriter:
    """Writes a dataset atomically: use as a context manager, `add` frames, leave the block.

    Leaving the block normally renames the temporary folder onto `out`; an
    exception (or Ctrl-C) removes it, and whatever stood at `out` before is kept.
    """

    def __init__(self, out: str | Path, camera: UAVCamera, meta: dict[str, Any],
                 overwrite: bool = False) -> None:
        self.out = Path(out)
        self.camera = camera
        self.meta = dict(meta)
        self.overwrite = overwrite
        self._frames: list[dict[str, Any]] = []
        self._tmp: Path | None = None
        check_output_folder(self.out, overwrite)

    def __enter__(self) -> DatasetWriter:
        self.out.parent.mkdir(parents=True, exist_ok=True)
        self._tmp = Path(tempfile.mkdtemp(prefix=f".{self.out.name}.tmp-", dir=self.out.parent))
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
        cv2.imwrite(str(self._tmp / "depth" / name), depth_to_png(depth))
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
            shutil.rmtree(self._tmp, ignore_errors=True)
            return
        try:
            write_json(self._tmp / "transforms.json", transforms_json(self.camera, self._frames, self.meta))
            replace_folder(self._tmp, self.out)
        except BaseException:
            shutil.rmtree(self._tmp, ignore_errors=True)
            raise


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
        "frames": frames,
        "nbv": {"version": FORMAT_VERSION, "focal_mm": camera.focal_mm, "near_m": camera.near_m,
                "far_m": camera.far_m, **meta},
    }


def check_output_folder(out: Path, overwrite: bool) -> None:
    """Fail early, naming the folder, if `out` cannot be written or would lose existing data."""
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"output {out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise FileExistsError(f"output folder {out} exists and is not empty (use --overwrite)")
    parent = out.parent
    while not parent.exists():
        parent = parent.parent
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PermissionError(f"output folder {out} is not writable (no write access to {parent})")


def replace_folder(src: Path, dst: Path) -> None:
    """Move the finished folder `src` onto `dst`, removing the old `dst` only afterwards."""
    old = None
    if dst.exists():
        old = dst.with_name(f".{dst.name}.old-{os.getpid()}")
        dst.rename(old)
    src.rename(dst)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def read_dataset(path: str | Path) -> ViewDataset:
    """Read and validate a dataset folder; errors name the file and the field at fault."""
    root = Path(path)
    doc_path = root / "transforms.json"
    if not doc_path.is_file():
        raise DatasetError(f"{doc_path}: not found (is {root} a view dataset?)")
    try:
        doc = json.loads(doc_path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise DatasetError(f"{doc_path}: corrupt JSON: {err}") from err
    if not isinstance(doc, dict):
        raise DatasetError(f"{doc_path}: top level must be an object")
    nbv = doc.get("nbv", {})
    camera = _read_camera(doc, nbv, doc_path)
    raw_frames = _field(doc, "frames", list, doc_path)
    frames = tuple(_read_frame(root, i, f, doc_path) for i, f in enumerate(raw_frames))
    return ViewDataset(root, camera, frames, dict(nbv))


def _field(obj: dict, key: str, kind: type | tuple[type, ...], where: Path, prefix: str = "") -> Any:
    if key not in obj:
        raise DatasetError(f"{where}: field {prefix}{key} is missing")
    value = obj[key]
    if not isinstance(value, kind) or isinstance(value, bool):
        raise DatasetError(f"{where}: field {prefix}{key} has the wrong type ({type(value).__name__})")
    return value


def _read_camera(doc: dict, nbv: dict, where: Path) -> UAVCamera:
    number = (int, float)
    w, h = _field(doc, "w", int, where), _field(doc, "h", int, where)
    fl_x = _field(doc, "fl_x", number, where)
    if not np.isclose(_field(doc, "fl_y", number, where), fl_x, rtol=1e-6):
        raise DatasetError(f"{where}: fields fl_x and fl_y differ; the UAV camera has square pixels")
    for key, size in (("cx", w), ("cy", h)):
        if not np.isclose(_field(doc, key, number, where), size / 2.0, atol=1e-3):
            raise DatasetError(f"{where}: field {key} is off-centre; the UAV camera is centred")
    try:
        focal_mm = float(nbv.get("focal_mm", fl_x * 36.0 / w)) if w > 0 else float("nan")
        return UAVCamera(w, h, focal_mm, float(nbv.get("near_m", 0.05)), float(nbv.get("far_m", 10.0)))
    except (TypeError, ValueError) as err:
        raise DatasetError(f"{where}: camera fields: {err}") from err


def _read_frame(root: Path, i: int, frame: Any, where: Path) -> Frame:
    prefix = f"frames[{i}]."
    if not isinstance(frame, dict):
        raise DatasetError(f"{where}: frames[{i}] must be an object")
    paths = []
    for key in ("file_path", "depth_file_path"):
        p = root / _field(frame, key, str, where, prefix)
        if not p.is_file():
            raise DatasetError(f"{where}: {prefix}{key} names a missing file {p}")
        paths.append(p)
    try:
        matrix = np.asarray(_field(frame, "transform_matrix", list, where, prefix), dtype=np.float64)
        c2w = validate_pose(opencv_to_opengl(matrix), f"{prefix}transform_matrix")
    except ValueError as err:
        raise DatasetError(f"{where}: {err}") from err
    meta = frame.get("nbv", {})
    view = None
    if "viewpoint" in meta:
        try:
            view = Viewpoint(*map(float, meta["viewpoint"]))
        except (TypeError, ValueError) as err:
            raise DatasetError(f"{where}: {prefix}nbv.viewpoint: {err}") from err
    return Frame(paths[0], paths[1], c2w, view, dict(meta))


def iter_views(dataset: ViewDataset) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(rgb, depth, c2w) for every frame, in order."""
    for i, frame in enumerate(dataset.frames):
        yield dataset.rgb(i), dataset.depth(i), frame.c2w


def write_subset(dataset: ViewDataset, indices: list[int], out: str | Path,
                 meta: dict[str, Any], overwrite: bool = False) -> None:
    """Write the frames `indices` of `dataset` as a new dataset (frames record `source_index`)."""
    merged = {**dataset.meta, **meta}
    with DatasetWriter(out, dataset.camera, merged, overwrite) as writer:
        for i in indices:
            frame = dataset.frames[i]
            writer.add(dataset.rgb(i), dataset.depth(i), frame.c2w, frame.viewpoint,
                       {**frame.meta, "source_index": int(i)})
