"""Export of a view dataset as a COLMAP model (`nbv export DATASET --format colmap`; docs/data-formats.md).

The output folder holds `images/` (the dataset's RGB images, copied or linked)
and `sparse/0/` with `cameras`, `images` and `points3D` in COLMAP's text and
binary formats. COLMAP's conventions: one PINHOLE camera (fx, fy, cx, cy) with
pixel centres at +0.5, so cx = cx_opencv + 0.5 (= transforms.json's `cx`);
poses world-to-camera in OpenCV axes, rotation as a unit quaternion with w
first (w >= 0). Points are back-projected from the depth maps: a seeded
random subset of each view's pixels with depth, coloured from its RGB, each
observed once (a track of length 1) at the pixel it came from.
"""

from __future__ import annotations

import os
import shutil
import struct
import unicodedata
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from scipy.spatial.transform import Rotation
from tyro.conf import Positional, arg

from common.io import atomic_folder, check_separate
from render.dataset import ViewDataset, check_output_folder, read_dataset

PINHOLE_MODEL_ID = 1
"""COLMAP's id of the PINHOLE camera model (params fx, fy, cx, cy)."""
NO_POINT = 2**64 - 1
"""COLMAP's point3D id of a 2D point without a 3D point (-1 as uint64)."""
MODEL_FILES = ("cameras", "images", "points3D")
"""The model's files, each written as `.txt` and `.bin` under `sparse/0/`."""


@dataclass(frozen=True, kw_only=True)
class ExportConfig:
    """Settings of `nbv export`: the dataset, the format, what to include and where to write it."""

    dataset: Annotated[Path, Positional, arg(metavar="DATASET")]
    """A view dataset folder (transforms.json, images/, depth/), e.g. from `nbv scan`."""
    out: Path
    """Output folder, written atomically (images/, sparse/0/{cameras,images,points3D}.{txt,bin})."""
    format: Literal["colmap"] = "colmap"
    """Export format: a COLMAP model with PINHOLE intrinsics and known poses."""
    images: Literal["link", "copy"] = "link"
    """Put the RGB images in OUT/images as symbolic links to the dataset's files, or as copies."""
    points: bool = True
    """Back-project points3D from the depth maps (--no-points writes an empty points3D)."""
    points_per_view: int = 2000
    """Most depth pixels per view turned into 3D points (a seeded random subset)."""
    seed: int = 0
    """Seed of the pixel subsampling."""
    overwrite: bool = False
    """Replace an existing non-empty output folder (only once the new export is complete)."""

    def __post_init__(self) -> None:
        if self.points_per_view < 1:
            raise ValueError(f"points_per_view must be >= 1, got {self.points_per_view}")
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}")


@dataclass(frozen=True)
class ColmapModel:
    """A COLMAP model in memory: one PINHOLE camera, posed images, coloured points with tracks."""

    width: int
    """Image width in pixels."""
    height: int
    """Image height in pixels."""
    params: tuple[float, float, float, float]
    """PINHOLE fx, fy, cx, cy (pixel centres at +0.5)."""
    names: tuple[str, ...]
    """Image file names under images/, in image-id order (ids from 1)."""
    quats: np.ndarray
    """(N, 4) world-to-camera rotations, quaternions w first."""
    trans: np.ndarray
    """(N, 3) world-to-camera translations."""
    xyz: np.ndarray
    """(P, 3) float64 point positions (point ids from 1)."""
    rgb: np.ndarray
    """(P, 3) uint8 point colours."""
    image_of: np.ndarray
    """(P,) image index (from 0) observing each point."""
    pixels: np.ndarray
    """(P, 2) float64 observation in COLMAP pixel coordinates (centres at +0.5)."""


def export_dataset(config: ExportConfig) -> Path:
    """Write the COLMAP model of `config.dataset` atomically at `config.out`; return the folder."""
    out = Path(config.out)
    check_writable(out, config.overwrite)
    source = Path(config.dataset).resolve()
    if out.resolve() == source or out.resolve() in source.parents:
        raise ValueError(f"output folder {out} would replace the dataset {config.dataset} it exports")
    check_separate(out, config.dataset)  # an export inside the dataset would become part of it
    dataset = read_dataset(config.dataset)
    model = build_model(dataset, config.points_per_view if config.points else 0, config.seed)
    with atomic_folder(out, config.overwrite) as tmp:
        place_images(dataset, tmp / "images", config.images)
        sparse = tmp / "sparse" / "0"
        sparse.mkdir(parents=True)
        write_text_model(model, sparse)
        write_binary_model(model, sparse)
    return out


def check_writable(out: Path, overwrite: bool) -> None:
    """Fail before any work, naming the path, if `out` cannot be created or would lose data."""
    ancestor = out.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise PermissionError(f"output folder {out} cannot be created: {ancestor} is a file, not a folder")
    check_output_folder(out, overwrite)


def world_to_camera(c2w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """COLMAP's pose of an OpenCV camera-to-world: (qw, qx, qy, qz) with qw >= 0 and t, both float64.

    Example:
        >>> q, t = world_to_camera(np.diag([1.0, -1.0, -1.0, 1.0]))
        >>> q.round(6).tolist(), t.tolist()
        ([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    """
    rot = c2w[:3, :3].T
    x, y, z, w = Rotation.from_matrix(rot).as_quat(canonical=True)
    return np.array([w, x, y, z]), -rot @ c2w[:3, 3]


def back_project(depth: np.ndarray, K: np.ndarray, c2w: np.ndarray, count: int,  # noqa: N803
                 rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Up to `count` random pixels with depth: their (M, 2) integer (u, v) and (M, 3) world points."""
    v, u = np.nonzero(depth > 0)
    if len(u) > count:
        keep = np.sort(rng.choice(len(u), size=count, replace=False))
        u, v = u[keep], v[keep]
    z = depth[v, u].astype(np.float64)
    cam = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z], -1)
    return np.stack([u, v], -1), cam @ c2w[:3, :3].T + c2w[:3, 3]


def build_model(dataset: ViewDataset, points_per_view: int, seed: int) -> ColmapModel:
    """The COLMAP model of a dataset; `points_per_view` 0 leaves the points empty."""
    camera, rng = dataset.camera, np.random.default_rng(seed)
    k = camera.K
    names = tuple(colmap_name(frame.rgb_path) for frame in dataset.frames)
    if len(set(names)) < len(names):
        raise ValueError(f"{dataset.root}: image file names repeat; COLMAP names images by file name")
    poses = [world_to_camera(frame.c2w) for frame in dataset.frames]
    xyz, pixels = [np.zeros((0, 3))], [np.zeros((0, 2))]
    rgb, image_of = [np.zeros((0, 3), np.uint8)], [np.zeros(0, np.int64)]
    for i, frame in enumerate(dataset.frames if points_per_view else ()):
        uv, world = back_project(dataset.depth(i), k, frame.c2w, points_per_view, rng)
        xyz.append(world)
        rgb.append(dataset.rgb(i)[uv[:, 1], uv[:, 0]])
        image_of.append(np.full(len(uv), i))
        pixels.append(uv + 0.5)
    return ColmapModel(
        camera.width, camera.height, (camera.fx, camera.fx, k[0, 2] + 0.5, k[1, 2] + 0.5),
        names,
        np.array([q for q, _ in poses]).reshape(-1, 4), np.array([t for _, t in poses]).reshape(-1, 3),
        np.concatenate(xyz), np.concatenate(rgb), np.concatenate(image_of), np.concatenate(pixels))


def colmap_name(path: Path) -> str:
    """The file name of `path` as COLMAP's images.txt writes it, refused (ValueError naming the file) when
    it holds whitespace or a control character: the text format splits fields at spaces, lines at
    newlines."""
    name = path.name
    if any(c.isspace() or unicodedata.category(c) in ("Cc", "Cs") for c in name):
        raise ValueError(f"{path}: COLMAP's images.txt cannot hold the image name {ascii(name)} (fields are "
                         f"split at spaces, lines at newlines); rename it without spaces or control "
                         f"characters")
    return name


def place_images(dataset: ViewDataset, folder: Path, mode: str) -> None:
    """Copy the dataset's RGB images into `folder`, or link them there (absolute links)."""
    folder.mkdir(parents=True)
    for frame in dataset.frames:
        target = folder / frame.rgb_path.name
        if mode == "copy":
            shutil.copyfile(frame.rgb_path, target)
        else:
            os.symlink(frame.rgb_path.resolve(), target)


def _observations(model: ColmapModel) -> list[np.ndarray]:
    """Per image, the indices of the points it observes (its points2D, in order)."""
    return [np.flatnonzero(model.image_of == i) for i in range(len(model.names))]


def write_text_model(model: ColmapModel, folder: Path) -> None:
    """cameras.txt, images.txt and points3D.txt (COLMAP's text format, full float precision)."""
    observed = _observations(model)
    (folder / "cameras.txt").write_text(
        "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        f"# Number of cameras: 1\n1 PINHOLE {model.width} {model.height} {_numbers(model.params)}\n")
    mean_obs = len(model.xyz) / max(len(model.names), 1)
    lines = ["# Image list with two lines of data per image:",
             "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
             "#   POINTS2D[] as (X, Y, POINT3D_ID)",
             f"# Number of images: {len(model.names)}, mean observations per image: {mean_obs}"]
    for i, name in enumerate(model.names):
        lines.append(f"{i + 1} {_numbers((*model.quats[i], *model.trans[i]))} 1 {name}")
        lines.append(" ".join(f"{_numbers(model.pixels[p])} {p + 1}" for p in observed[i]))
    (folder / "images.txt").write_text("\n".join(lines) + "\n")
    index_in_image = _index_in_image(model, observed)
    lines = ["# 3D point list with one line of data per point:",
             "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)",
             f"# Number of points: {len(model.xyz)}, mean track length: {1.0 if len(model.xyz) else 0.0}"]
    for p in range(len(model.xyz)):
        r, g, b = (int(c) for c in model.rgb[p])
        lines.append(f"{p + 1} {_numbers(model.xyz[p])} {r} {g} {b} 0.0 {model.image_of[p] + 1} "
                     f"{index_in_image[p]}")
    (folder / "points3D.txt").write_text("\n".join(lines) + "\n")


def _numbers(values: Iterable[float]) -> str:
    """Floats separated by spaces, each written with every digit needed to read it back exactly."""
    return " ".join(repr(float(v)) for v in values)


def _index_in_image(model: ColmapModel, observed: list[np.ndarray]) -> np.ndarray:
    """For each point, its index among its image's points2D."""
    index = np.zeros(len(model.xyz), dtype=np.int64)
    for points in observed:
        index[points] = np.arange(len(points))
    return index


def write_binary_model(model: ColmapModel, folder: Path) -> None:
    """cameras.bin, images.bin and points3D.bin (COLMAP's little-endian binary format)."""
    observed = _observations(model)
    with open(folder / "cameras.bin", "wb") as f:
        f.write(struct.pack("<QIiQQ4d", 1, 1, PINHOLE_MODEL_ID, model.width, model.height, *model.params))
    with open(folder / "images.bin", "wb") as f:
        f.write(struct.pack("<Q", len(model.names)))
        for i, name in enumerate(model.names):
            f.write(struct.pack("<I7dI", i + 1, *model.quats[i], *model.trans[i], 1))
            f.write(name.encode() + b"\0")
            f.write(struct.pack("<Q", len(observed[i])))
            rows = np.zeros(len(observed[i]), dtype=[("x", "<f8"), ("y", "<f8"), ("id", "<u8")])
            rows["x"], rows["y"] = model.pixels[observed[i], 0], model.pixels[observed[i], 1]
            rows["id"] = observed[i] + 1
            f.write(rows.tobytes())
    index_in_image = _index_in_image(model, observed)
    rows = np.zeros(len(model.xyz), dtype=[("id", "<u8"), ("xyz", "<f8", 3), ("rgb", "u1", 3),
                                           ("error", "<f8"), ("track", "<u8"), ("image", "<u4"),
                                           ("point2d", "<u4")])
    rows["id"] = np.arange(1, len(model.xyz) + 1)
    rows["xyz"], rows["rgb"], rows["track"] = model.xyz, model.rgb, 1
    rows["image"], rows["point2d"] = model.image_of + 1, index_in_image
    with open(folder / "points3D.bin", "wb") as f:
        f.write(struct.pack("<Q", len(model.xyz)))
        f.write(rows.tobytes())
