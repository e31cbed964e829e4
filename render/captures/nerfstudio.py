"""A nerfstudio capture: `transforms.json` as ns-process-data, Polycam and Record3D write it.

Intrinsics (`fl_x`, `fl_y`, `cx`, `cy`, `w`, `h`, `k1`-`k4`, `p1`, `p2`, `camera_model`) are the
document's, a frame's own values overriding them (per-frame intrinsics). `transform_matrix` is an
OpenGL camera-to-world in any world frame; `applied_transform` is kept as it is (it names a frame,
and any frame will do). Depth and masks are not read. The kept subset is written as the same
document with only the kept frames, their files (image, and depth and mask where given) copied.
"""

from __future__ import annotations

import copy
import shutil
from pathlib import Path
from typing import Any

from common.io import atomic_folder, write_json
from render.captures.dataset import CaptureDataset, build_capture
from render.captures.frame import CaptureFrameConfig
from render.captures.images import Intrinsics, check_intrinsics
from render.dataset_read import DatasetError, contained_file, read_pose, to_float, typed_field

CAMERA_MODELS = ("OPENCV", "PINHOLE", "SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL")
"""Camera models read (all as OpenCV's radial-tangential model with k1, k2, k3, p1, p2)."""
FRAME_FILES = ("file_path", "depth_file_path", "mask_path")
"""A frame's files, copied with it when written back (depth and mask only where present)."""


def _intrinsics(doc: dict, frame: dict, where: Path, prefix: str) -> Intrinsics:
    """Frame `prefix`'s camera: its own fields, else the document's."""
    def value(key: str, kind: type = float, default: Any = None) -> Any:
        source, name = (frame, prefix + key) if key in frame else (doc, key)
        if key not in source:
            if default is not None:
                return default
            raise DatasetError(f"{where}: field {key} is missing (at the top level or in {prefix[:-1]})")
        if kind is int:
            return typed_field(source, key, int, where, "" if source is doc else prefix)
        return to_float(source[key], where, name)

    model = frame.get("camera_model", doc.get("camera_model", "OPENCV"))
    if model not in CAMERA_MODELS:
        raise DatasetError(f"{where}: field camera_model {model!r} is not supported; use one of "
                           f"{', '.join(CAMERA_MODELS)} (fisheye and equirectangular images are not read)")
    if value("k4", default=0.0) != 0.0:
        raise DatasetError(f"{where}: field k4 is not 0; k4 is a fisheye coefficient, not OPENCV's")
    k1, k2, k3, p1, p2 = (value(key, default=0.0) for key in ("k1", "k2", "k3", "p1", "p2"))
    fl_x = value("fl_x")
    intr = Intrinsics(value("w", int), value("h", int), fl_x, value("fl_y", default=fl_x),
                      value("cx") - 0.5, value("cy") - 0.5, (k1, k2, p1, p2, k3) if k3 else (k1, k2, p1, p2))
    return check_intrinsics(intr, where, f"{prefix[:-1]}'s camera")


def read_nerfstudio_capture(root: Path, doc: dict[str, Any], config: CaptureFrameConfig) -> CaptureDataset:
    """The capture of the parsed `root/transforms.json` `doc`, its frames in the document's order."""
    where = root / "transforms.json"
    raw = typed_field(doc, "frames", list, where)
    if not raw:
        raise DatasetError(f"{where}: field frames is empty (a capture needs at least one view)")
    views = []
    for i, frame in enumerate(raw):
        prefix = f"frames[{i}]."
        if not isinstance(frame, dict):
            raise DatasetError(f"{where}: frames[{i}] must be an object")
        path = contained_file(root, typed_field(frame, "file_path", str, where, prefix), where,
                              prefix + "file_path")
        views.append((path, read_pose(frame, where, prefix), _intrinsics(doc, frame, where, prefix)))
    return build_capture(root, "nerfstudio", where, views, list(range(len(raw))), doc, config)


def write_nerfstudio_subset(dataset: CaptureDataset, indices: list[int], out: Path, overwrite: bool,
                            extra: dict[str, Any]) -> None:
    """The frames `indices` as a nerfstudio capture at `out` (files copied), with the `extra` documents."""
    doc = copy.deepcopy(dataset.source)
    doc["frames"] = [doc["frames"][dataset.keys[i]] for i in indices]
    with atomic_folder(out, overwrite) as tmp:
        for frame in doc["frames"]:
            for key in FRAME_FILES:
                _copy_inside(dataset.root, frame.get(key), tmp)
        if not _copy_inside(dataset.root, doc.get("ply_file_path"), tmp):
            doc.pop("ply_file_path", None)  # a point cloud named but absent would stop nerfstudio
        write_json(tmp / "transforms.json", doc)
        for name, extra_doc in extra.items():
            write_json(tmp / name, extra_doc)


def _copy_inside(root: Path, value: Any, out: Path) -> bool:
    """Copy `root / value` to `out / value` when it is a file inside `root`; whether it was copied."""
    if not isinstance(value, str) or not value:
        return False
    try:
        source = contained_file(root, value, root / "transforms.json", value)
    except DatasetError:
        return False
    target = out / value
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(source, target)
    return True
