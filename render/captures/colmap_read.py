"""Reading a COLMAP model's text or binary files (`cameras`, `images`, `points3D`) into a `Model`.

Binary is read where both are present, as COLMAP does. A model without `points3D` reads as one with
no points. Every failure is a `DatasetError` naming the file and the record.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from render.captures.colmap_model import (
    ByteReader,
    Camera,
    Image,
    Model,
    Points,
    camera_model,
    check_image,
    check_model,
    read_bytes,
)
from render.dataset_read import DatasetError

_POINT2D = np.dtype([("x", "<f8"), ("y", "<f8"), ("id", "<u8")])
_TRACK = np.dtype([("image", "<u4"), ("point2d", "<u4")])
NO_POINTS = Points(np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3), np.uint8), np.zeros(0), ())
"""The points of a model without a points3D file."""


def model_kind(folder: Path) -> str | None:
    """"binary" or "text" for the files present in `folder` (binary preferred), None if neither."""
    for kind, ext in (("binary", "bin"), ("text", "txt")):
        if (folder / f"cameras.{ext}").is_file() and (folder / f"images.{ext}").is_file():
            return kind
    return None


def read_model(folder: Path) -> Model:
    """The checked COLMAP model in `folder`."""
    kind = model_kind(folder)
    if kind is None:
        raise DatasetError(f"{folder}: no COLMAP model (expected cameras.bin and images.bin, or cameras.txt "
                           f"and images.txt)")
    ext = "bin" if kind == "binary" else "txt"
    readers: dict[str, Callable] = (
        {"cameras": _binary_cameras, "images": _binary_images, "points3D": _binary_points} if kind == "binary"
        else {"cameras": _text_cameras, "images": _text_images, "points3D": _text_points})
    cameras = readers["cameras"](folder / f"cameras.{ext}")
    images = readers["images"](folder / f"images.{ext}")
    points_path = folder / f"points3D.{ext}"
    points = readers["points3D"](points_path) if points_path.exists() else NO_POINTS
    return check_model(Model(cameras, images, points, kind), folder)


def _camera(camera_id: int, model: str | int, width: int, height: int, params: list[float],
            where: Path) -> Camera:
    """A checked camera record."""
    record = f"camera {camera_id}"
    name, expected = camera_model(model, where, record)
    if len(params) != expected:
        raise DatasetError(f"{where}: {record} has {len(params)} parameters, {name} takes {expected}")
    if not all(math.isfinite(p) for p in params):
        raise DatasetError(f"{where}: {record} has NaN or infinite parameters {params}")
    if width < 1 or height < 1:
        raise DatasetError(f"{where}: {record} has size {width}x{height}")
    if not 0 <= camera_id < 2**32:
        raise DatasetError(f"{where}: {record}'s id is outside [0, 2^32)")
    return Camera(camera_id, name, width, height, tuple(params))


def _add(table: dict, key: int, value, where: Path, what: str) -> None:
    if key in table:
        raise DatasetError(f"{where}: {what} id {key} appears twice")
    table[key] = value


def _binary_cameras(path: Path) -> dict[int, Camera]:
    reader, cameras = ByteReader(path), {}
    for _ in range(reader.count(24, "cameras")):
        camera_id, model_id, width, height = reader.take("IiQQ")
        _, count = camera_model(model_id, path, f"camera {camera_id}")
        params = list(reader.take(f"{count}d"))
        _add(cameras, camera_id, _camera(camera_id, model_id, width, height, params, path), path, "camera")
    reader.finish()
    return cameras


def _binary_images(path: Path) -> dict[int, Image]:
    reader, images = ByteReader(path), {}
    for _ in range(reader.count(73, "images")):
        image_id, qw, qx, qy, qz, tx, ty, tz, camera_id = reader.take("I7dI")
        name = reader.name()
        rows = reader.array(_POINT2D, reader.count(24, f"points2D of image {image_id}"))
        ids = rows["id"].astype(np.int64)  # 2^64 - 1 wraps to -1 (NO_POINT)
        xy = np.stack([rows["x"], rows["y"]], -1).astype(np.float64).reshape(-1, 2)
        image = check_image(Image(image_id, (qw, qx, qy, qz), (tx, ty, tz), camera_id, name, xy, ids), path)
        _add(images, image_id, image, path, "image")
    reader.finish()
    return images


def _binary_points(path: Path) -> Points:
    reader = ByteReader(path)
    ids, xyz, rgb, error, tracks = [], [], [], [], []
    for _ in range(reader.count(51, "points3D")):
        pid, x, y, z, r, g, b, err = reader.take("Q3d3Bd")
        track = reader.array(_TRACK, reader.count(8, f"track entries of point3D {pid}"))
        ids.append(pid), xyz.append((x, y, z)), rgb.append((r, g, b)), error.append(err)
        tracks.append(np.stack([track["image"], track["point2d"]], -1).astype(np.int64).reshape(-1, 2))
    reader.finish()
    return _points(ids, xyz, rgb, error, tracks, path)


def _points(ids, xyz, rgb, error, tracks, path: Path) -> Points:
    if any(not 0 <= pid < 2**63 for pid in ids):
        raise DatasetError(f"{path}: a point3D id is outside [0, 2^63)")
    return Points(np.array(ids, np.int64), np.array(xyz, np.float64).reshape(-1, 3),
                  np.array(rgb, np.uint8).reshape(-1, 3), np.array(error, np.float64), tuple(tracks))


def _lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of every line of a text model file."""
    try:
        text = read_bytes(path).decode("utf-8")
    except UnicodeDecodeError as err:
        raise DatasetError(f"{path}: not UTF-8 text ({err})") from err
    return [(n + 1, line.strip()) for n, line in enumerate(text.splitlines())]


def _numbers(tokens: list[str], kinds: str, path: Path, line: int) -> list:
    """`tokens` as ints ("i") and floats ("f") by `kinds`; a `DatasetError` naming the line otherwise."""
    try:
        values = [int(t) if k == "i" else float(t) for t, k in zip(tokens, kinds, strict=True)]
    except ValueError as err:
        raise DatasetError(f"{path}: line {line}: {err} (expected {len(kinds)} numbers)") from err
    if any(isinstance(v, float) and not math.isfinite(v) for v in values):
        raise DatasetError(f"{path}: line {line}: NaN or infinite value in {' '.join(tokens)}")
    return values


def _text_cameras(path: Path) -> dict[int, Camera]:
    cameras = {}
    for line, text in _lines(path):
        if not text or text.startswith("#"):
            continue
        tokens = text.split()
        if len(tokens) < 4:
            raise DatasetError(f"{path}: line {line}: expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]")
        camera_id, width, height = _numbers([tokens[0], *tokens[2:4]], "iii", path, line)
        params = _numbers(tokens[4:], "f" * len(tokens[4:]), path, line)
        _add(cameras, camera_id, _camera(camera_id, tokens[1], width, height, params, path), path, "camera")
    return cameras


def _text_images(path: Path) -> dict[int, Image]:
    lines, images, i = _lines(path), {}, 0
    while i < len(lines):
        line, text = lines[i]
        i += 1
        if not text or text.startswith("#"):
            continue
        tokens = text.split()
        if len(tokens) != 10:
            raise DatasetError(f"{path}: line {line}: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME "
                               f"(10 fields, no spaces in NAME), got {len(tokens)}")
        values = _numbers(tokens[:9], "ifffffffi", path, line)
        points = lines[i][1].split() if i < len(lines) else []
        i += 1
        if len(points) % 3:
            raise DatasetError(f"{path}: line {line + 1}: POINTS2D must be triples X Y POINT3D_ID")
        rows = _numbers(points, "ffi" * (len(points) // 3), path, line + 1)
        xy = np.array([rows[k:k + 2] for k in range(0, len(rows), 3)], np.float64).reshape(-1, 2)
        ids = np.array(rows[2::3], np.int64)
        image = check_image(Image(values[0], tuple(values[1:5]), tuple(values[5:8]), values[8], tokens[9],
                                  xy, ids), path)
        _add(images, values[0], image, path, "image")
    return images


def _text_points(path: Path) -> Points:
    ids, xyz, rgb, error, tracks = [], [], [], [], []
    for line, text in _lines(path):
        if not text or text.startswith("#"):
            continue
        tokens = text.split()
        if len(tokens) < 8 or len(tokens) % 2:
            raise DatasetError(f"{path}: line {line}: expected POINT3D_ID X Y Z R G B ERROR TRACK[] pairs")
        values = _numbers(tokens, "ifffiiif" + "i" * (len(tokens) - 8), path, line)
        if not all(0 <= c <= 255 for c in values[4:7]) or values[0] < 0:
            raise DatasetError(f"{path}: line {line}: colour outside 0-255 or negative id")
        ids.append(values[0]), xyz.append(values[1:4]), rgb.append(values[4:7]), error.append(values[7])
        tracks.append(np.array(values[8:], np.int64).reshape(-1, 2))
    return _points(ids, xyz, rgb, error, tracks, path)

