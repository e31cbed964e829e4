"""A COLMAP capture: `ROOT/images/` beside `ROOT/sparse/0/` (or `ROOT/sparse/`), read and written back.

Frames are the model's images in name order (capture order for the usual numbered names). Each
camera model's parameters map to OpenCV intrinsics and distortion (COLMAP's principal point is
+0.5-centred). The kept subset is written as `OUT/images/` (copies) and `OUT/sparse/0/`, in the
format read, plus any extra documents (refine.json).
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from common.io import atomic_folder, write_json
from render.captures.colmap_model import Camera, Image, Model
from render.captures.colmap_read import model_kind, read_model
from render.captures.colmap_write import model_subset, write_model
from render.captures.dataset import CaptureDataset, build_capture
from render.captures.frame import CaptureFrameConfig
from render.captures.images import Intrinsics, check_intrinsics
from render.dataset_read import DatasetError, contained_file


def find_colmap(path: Path) -> tuple[Path, Path] | None:
    """(model folder, images folder) of a COLMAP capture at `path`, None if `path` holds no model.

    `path` is the capture's root (`sparse/0/` or `sparse/` in it) or the model folder itself, whose
    images are looked for beside it and up to two levels up."""
    for model in (path / "sparse" / "0", path / "sparse", path):
        if model_kind(model) is not None:
            break
    else:
        return None
    for folder in (path, path.parent, path.parent.parent) if model == path else (path,):
        if (folder / "images").is_dir():
            return model, folder / "images"
    raise DatasetError(f"{model}: a COLMAP model without an images/ folder beside it (expected "
                       f"ROOT/images/ with ROOT/sparse/0/)")


def intrinsics(camera: Camera, where: Path) -> Intrinsics:
    """OpenCV intrinsics and distortion of a COLMAP camera."""
    p = camera.params
    if camera.model in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL"):
        fx = fy = p[0]
        cx, cy, extra = p[1], p[2], p[3:]  # extra: k (SIMPLE_RADIAL) or k1, k2 (RADIAL)
    else:
        (fx, fy, cx, cy), extra = p[:4], p[4:]  # extra: k1, k2, p1, p2 (OPENCV) and k3-k6 (FULL_OPENCV)
    coeffs = extra if len(extra) >= 4 else (*extra, 0.0, 0.0, 0.0, 0.0)[:4]
    intr = Intrinsics(camera.width, camera.height, fx, fy, cx - 0.5, cy - 0.5, tuple(coeffs))
    return check_intrinsics(intr, where, f"camera {camera.camera_id} ({camera.model})")


def camera_to_world(image: Image) -> np.ndarray:
    """The OpenCV camera-to-world of a COLMAP image (world-to-camera quaternion w first, translation)."""
    w, x, y, z = image.qvec
    rot = Rotation.from_quat([x, y, z, w]).as_matrix()
    c2w = np.eye(4)
    c2w[:3, :3], c2w[:3, 3] = rot.T, -rot.T @ np.asarray(image.tvec)
    return c2w


def read_colmap_capture(path: Path, config: CaptureFrameConfig) -> CaptureDataset:
    """The COLMAP capture at `path` (see `find_colmap`), its frames in image-name order."""
    found = find_colmap(path)
    if found is None:
        raise DatasetError(f"{path}: no COLMAP model (sparse/0/ with cameras, images, points3D)")
    model_dir, images_dir = found
    model = read_model(model_dir)
    where = model_dir / f"images.{'bin' if model.kind == 'binary' else 'txt'}"
    cams = {cid: intrinsics(cam, model_dir / "cameras") for cid, cam in model.cameras.items()}
    order = sorted(model.images.values(), key=lambda image: image.name)
    views = [(contained_file(images_dir, image.name, where, f"image {image.image_id} name"),
              camera_to_world(image), cams[image.camera_id]) for image in order]
    return build_capture(path, "colmap", where, views, [image.image_id for image in order],
                         (model, images_dir), config)


def write_colmap_subset(dataset: CaptureDataset, indices: list[int], out: Path, overwrite: bool,
                        extra: dict[str, Any]) -> None:
    """The frames `indices` as a COLMAP capture at `out` (images copied), with the `extra` documents."""
    model, images_dir = dataset.source
    subset: Model = model_subset(model, [dataset.keys[i] for i in indices])
    with atomic_folder(out, overwrite) as tmp:
        for image in subset.images.values():
            target = tmp / "images" / image.name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(images_dir / image.name, target)
        (tmp / "sparse" / "0").mkdir(parents=True)
        write_model(subset, tmp / "sparse" / "0")
        for name, doc in extra.items():
            write_json(tmp / name, doc)
