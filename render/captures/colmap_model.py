"""A COLMAP model (cameras, images, points3D) in memory, with strict readers of its text and binary files.

The readers follow COLMAP's layouts (`colmap/scene/reconstruction_io_{text,binary}.cc`) and check
every count against the bytes left, every number for being finite, every id for being unique and
every reference (an image's camera, a point's track, an observation's point) for existing, so a
corrupt model is a `DatasetError` naming the file and the record, never a crash or a huge allocation.
`rigs` and `frames` files (COLMAP 3.12+) are not read: each image is its own frame, as in older models.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from render.dataset_read import DatasetError

MODELS = {"SIMPLE_PINHOLE": (0, 3), "PINHOLE": (1, 4), "SIMPLE_RADIAL": (2, 4), "RADIAL": (3, 5),
          "OPENCV": (4, 8), "FULL_OPENCV": (6, 12)}
"""Camera models read (name: COLMAP model id, parameter count); the others (fisheye, FOV...) are refused."""
OTHER_MODELS = {5: "OPENCV_FISHEYE", 7: "FOV", 8: "SIMPLE_RADIAL_FISHEYE", 9: "RADIAL_FISHEYE",
                10: "THIN_PRISM_FISHEYE", 11: "RAD_TAN_THIN_PRISM_FISHEYE", 12: "SIMPLE_DIVISION",
                13: "DIVISION", 14: "SIMPLE_FISHEYE", 15: "FISHEYE", 16: "EUCM", 17: "EQUIRECTANGULAR"}
"""COLMAP's other camera models, named in the error that refuses them."""
NO_POINT = -1
"""point3D id of an observation without a 3D point (2^64 - 1 in the binary files)."""
MAX_MODEL_BYTES = 4 * 2**30
"""Largest model file read."""
MAX_COORD = 1e9
"""Largest absolute camera translation accepted (geo-registered models reach 1e7 m)."""


@dataclass(frozen=True)
class Camera:
    """One COLMAP camera."""

    camera_id: int
    """Its id."""
    model: str
    """Its model name (a key of `MODELS`)."""
    width: int
    """Image width, pixels."""
    height: int
    """Image height, pixels."""
    params: tuple[float, ...]
    """The model's parameters, in COLMAP's order and pixel convention (centres at +0.5)."""


@dataclass(frozen=True)
class Image:
    """One registered COLMAP image."""

    image_id: int
    """Its id."""
    qvec: tuple[float, float, float, float]
    """World-to-camera rotation, unit quaternion (w, x, y, z)."""
    tvec: tuple[float, float, float]
    """World-to-camera translation."""
    camera_id: int
    """Its camera's id."""
    name: str
    """File name under the images folder."""
    xy: np.ndarray
    """(P, 2) float64 keypoints (points2D), pixels."""
    point_ids: np.ndarray
    """(P,) int64 point3D id of each keypoint (`NO_POINT`: none)."""


@dataclass(frozen=True)
class Points:
    """The model's 3D points, one row each."""

    ids: np.ndarray
    """(M,) int64 point ids."""
    xyz: np.ndarray
    """(M, 3) float64 positions."""
    rgb: np.ndarray
    """(M, 3) uint8 colours."""
    error: np.ndarray
    """(M,) float64 reprojection errors."""
    tracks: tuple[np.ndarray, ...]
    """Per point, its (K, 2) int64 track: (image id, point2D index) rows."""


@dataclass(frozen=True)
class Model:
    """A COLMAP model and the format it was read from."""

    cameras: dict[int, Camera]
    """Cameras by id."""
    images: dict[int, Image]
    """Images by id."""
    points: Points
    """The 3D points."""
    kind: str
    """"text" or "binary": the format of the files read (and of the refined model written)."""


def camera_model(name_or_id: str | int, where: Path, record: str) -> tuple[str, int]:
    """(model name, parameter count) of a supported model; a `DatasetError` for another or an unknown one."""
    for name, (model_id, count) in MODELS.items():
        if name_or_id in (name, model_id):
            return name, count
    other = OTHER_MODELS.get(name_or_id) if isinstance(name_or_id, int) else name_or_id
    if other in OTHER_MODELS.values():
        raise DatasetError(f"{where}: {record} has camera model {other}, which is not supported; undistort "
                           f"the images first (colmap image_undistorter) or use one of {', '.join(MODELS)}")
    raise DatasetError(f"{where}: {record} has an unknown camera model {name_or_id!r} "
                       f"(supported: {', '.join(MODELS)})")


def check_image(image: Image, where: Path) -> Image:
    """`image` when its pose and keypoints are finite and its quaternion not zero (normalised)."""
    record = f"image {image.image_id} ({image.name!r})"
    pose = (*image.qvec, *image.tvec)
    if not all(math.isfinite(v) for v in pose):
        raise DatasetError(f"{where}: {record} has a NaN or infinite pose {pose}")
    if any(abs(v) > MAX_COORD for v in image.tvec):
        raise DatasetError(f"{where}: {record} has a translation beyond {MAX_COORD:g} {image.tvec}")
    if not (0 <= image.image_id < 2**32 and 0 <= image.camera_id < 2**32):
        raise DatasetError(f"{where}: {record} has an image or camera id outside [0, 2^32)")
    norm = math.sqrt(sum(q * q for q in image.qvec))
    if norm < 1e-9:
        raise DatasetError(f"{where}: {record} has a zero rotation quaternion")
    if not np.all(np.isfinite(image.xy)):
        raise DatasetError(f"{where}: {record} has NaN or infinite keypoints")
    if not image.name or "\0" in image.name:
        raise DatasetError(f"{where}: image {image.image_id} has an empty or invalid name")
    qvec = tuple(q / norm for q in image.qvec)
    return Image(image.image_id, qvec, image.tvec, image.camera_id, image.name, image.xy, image.point_ids)


def check_model(model: Model, where: Path) -> Model:
    """`model` when its ids are consistent: images' cameras exist, names are unique, every track names
    an existing image's keypoint, every keypoint's point exists."""
    if not model.images:
        raise DatasetError(f"{where}: the model has no images")
    names: set[str] = set()
    for image in model.images.values():
        if image.camera_id not in model.cameras:
            raise DatasetError(f"{where}: image {image.image_id} ({image.name!r}) names a missing camera "
                               f"{image.camera_id}")
        if image.name in names:
            raise DatasetError(f"{where}: image name {image.name!r} appears twice")
        names.add(image.name)
    points = model.points
    if len(np.unique(points.ids)) != len(points.ids):
        raise DatasetError(f"{where}: points3D ids repeat")
    if not (np.all(np.isfinite(points.xyz)) and np.all(np.isfinite(points.error))):
        raise DatasetError(f"{where}: points3D holds NaN or infinite positions or errors")
    for pid, track in zip(points.ids, points.tracks):
        for image_id, index in track:
            image = model.images.get(int(image_id))
            if image is None or not 0 <= index < len(image.xy):
                raise DatasetError(f"{where}: point3D {pid}'s track names image {image_id} keypoint {index}, "
                                   f"which does not exist")
    known = set(points.ids.tolist()) | {NO_POINT}
    for image in model.images.values():
        if not set(image.point_ids.tolist()) <= known:
            raise DatasetError(f"{where}: image {image.image_id} ({image.name!r}) observes a point3D that "
                               f"points3D does not hold")
    return model


class ByteReader:
    """Little-endian records from a binary model file; truncation and impossible counts are errors."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.data = read_bytes(path)
        self.pos = 0

    def take(self, fmt: str) -> tuple:
        """The next `struct` record of format `fmt` (little-endian)."""
        size = struct.calcsize("<" + fmt)
        if self.pos + size > len(self.data):
            raise DatasetError(f"{self.path}: truncated at byte {self.pos} (wanted {size} more bytes)")
        values = struct.unpack_from("<" + fmt, self.data, self.pos)
        self.pos += size
        return values

    def array(self, dtype: np.dtype, count: int) -> np.ndarray:
        """The next `count` records of the numpy structured `dtype`."""
        size = np.dtype(dtype).itemsize * count
        if self.pos + size > len(self.data):
            raise DatasetError(f"{self.path}: truncated at byte {self.pos} (wanted {size} more bytes)")
        rows = np.frombuffer(self.data, dtype, count, self.pos)
        self.pos += size
        return rows

    def count(self, min_bytes: int, what: str) -> int:
        """A uint64 record count, refused when `min_bytes` a record would not fit in what is left."""
        (n,) = self.take("Q")
        if n * min_bytes > len(self.data) - self.pos:
            raise DatasetError(f"{self.path}: claims {n} {what} but only {len(self.data) - self.pos} bytes "
                               f"follow (truncated or corrupt)")
        return n

    def name(self) -> str:
        """A NUL-terminated UTF-8 string."""
        end = self.data.find(b"\0", self.pos)
        if end < 0:
            raise DatasetError(f"{self.path}: truncated image name at byte {self.pos}")
        raw, self.pos = self.data[self.pos:end], end + 1
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError as err:
            raise DatasetError(f"{self.path}: image name at byte {self.pos} is not UTF-8") from err

    def finish(self) -> None:
        """Refuse bytes after the last record."""
        if self.pos != len(self.data):
            raise DatasetError(f"{self.path}: {len(self.data) - self.pos} stray bytes after the last record")


def read_bytes(path: Path) -> bytes:
    """The bytes of a model file no larger than `MAX_MODEL_BYTES`."""
    try:
        if not path.is_file():
            raise DatasetError(f"{path}: not a regular file")
        if path.stat().st_size > MAX_MODEL_BYTES:
            raise DatasetError(f"{path}: larger than {MAX_MODEL_BYTES} bytes")
        return path.read_bytes()
    except OSError as err:
        raise DatasetError(f"{path}: cannot read: {err}") from err
