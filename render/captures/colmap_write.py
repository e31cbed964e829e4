"""Writing the kept images of a COLMAP model as a model of their own, in the format it was read from.

The subset keeps the kept images' records as they were (ids, poses, keypoints), the cameras they use,
and the 3D points they observe, each point's track cut to the kept images; a point observed by no
kept image is dropped. Numbers are written with every digit (`repr`), so text round-trips exactly.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from render.captures.colmap_model import MODELS, NO_POINT, Image, Model, Points


def model_subset(model: Model, image_ids: list[int]) -> Model:
    """The model of the images `image_ids`: their cameras, the points they observe (tracks cut)."""
    kept = set(image_ids)
    images = {i: model.images[i] for i in image_ids}
    cameras = {c: model.cameras[c] for c in sorted({image.camera_id for image in images.values()})}
    rows, tracks = [], []
    for row, track in enumerate(model.points.tracks):
        cut = track[np.isin(track[:, 0], list(kept))] if len(track) else track
        if len(cut):
            rows.append(row)
            tracks.append(cut)
    points = model.points
    take = np.array(rows, np.int64)
    subset = Points(points.ids[take], points.xyz[take].reshape(-1, 3), points.rgb[take].reshape(-1, 3),
                    points.error[take], tuple(tracks))
    alive = set(subset.ids.tolist())
    images = {i: _without_dropped(image, alive) for i, image in images.items()}
    return Model(cameras, images, subset, model.kind)


def _without_dropped(image: Image, alive: set[int]) -> Image:
    """`image` whose keypoints no longer name a dropped point."""
    ids = np.array([p if p in alive else NO_POINT for p in image.point_ids.tolist()], np.int64)
    return Image(image.image_id, image.qvec, image.tvec, image.camera_id, image.name, image.xy, ids)


def write_model(model: Model, folder: Path) -> None:
    """cameras, images and points3D in `model.kind`'s format into the existing `folder`."""
    if model.kind == "binary":
        _write_binary(model, folder)
    else:
        _write_text(model, folder)


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _write_text(model: Model, folder: Path) -> None:
    cameras = ["# Camera list with one line of data per camera:",
               "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]", f"# Number of cameras: {len(model.cameras)}"]
    cameras += [f"{c.camera_id} {c.model} {c.width} {c.height} {_numbers(c.params)}"
                for c in model.cameras.values()]
    (folder / "cameras.txt").write_text("\n".join(cameras) + "\n")
    images = ["# Image list with two lines of data per image:",
              "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
              "#   POINTS2D[] as (X, Y, POINT3D_ID)",
              f"# Number of images: {len(model.images)}"]
    for im in model.images.values():
        images.append(f"{im.image_id} {_numbers((*im.qvec, *im.tvec))} {im.camera_id} {im.name}")
        images.append(" ".join(f"{_numbers(xy)} {pid}" for xy, pid in zip(im.xy, im.point_ids.tolist())))
    (folder / "images.txt").write_text("\n".join(images) + "\n")
    points = model.points
    lines = ["# 3D point list with one line of data per point:",
             "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)",
             f"# Number of points: {len(points.ids)}"]
    for k, pid in enumerate(points.ids.tolist()):
        r, g, b = (int(c) for c in points.rgb[k])
        track = " ".join(f"{i} {j}" for i, j in points.tracks[k].tolist())
        lines.append(f"{pid} {_numbers(points.xyz[k])} {r} {g} {b} {float(points.error[k])!r} {track}")
    (folder / "points3D.txt").write_text("\n".join(lines) + "\n")


def _write_binary(model: Model, folder: Path) -> None:
    with open(folder / "cameras.bin", "wb") as f:
        f.write(struct.pack("<Q", len(model.cameras)))
        for c in model.cameras.values():
            f.write(struct.pack(f"<IiQQ{len(c.params)}d", c.camera_id, MODELS[c.model][0], c.width, c.height,
                                *c.params))
    with open(folder / "images.bin", "wb") as f:
        f.write(struct.pack("<Q", len(model.images)))
        for image in model.images.values():
            f.write(struct.pack("<I7dI", image.image_id, *image.qvec, *image.tvec, image.camera_id))
            f.write(image.name.encode() + b"\0" + struct.pack("<Q", len(image.xy)))
            rows = np.zeros(len(image.xy), dtype=[("x", "<f8"), ("y", "<f8"), ("id", "<i8")])
            rows["x"], rows["y"], rows["id"] = image.xy[:, 0], image.xy[:, 1], image.point_ids
            f.write(rows.tobytes())  # id -1 is 2^64 - 1 as uint64, COLMAP's "no point"
    points = model.points
    with open(folder / "points3D.bin", "wb") as f:
        f.write(struct.pack("<Q", len(points.ids)))
        for k, pid in enumerate(points.ids.tolist()):
            f.write(struct.pack("<Q3d3BdQ", pid, *points.xyz[k], *points.rgb[k], points.error[k],
                                len(points.tracks[k])))
            f.write(points.tracks[k].astype("<u4").tobytes())
