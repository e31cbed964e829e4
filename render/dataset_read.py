"""Strict parsing of a view dataset's `transforms.json` and images (docs/data-formats.md §5).

Every field is type- and range-checked, every number finite, every file path
kept inside the dataset folder, and every PNG's header and chunk checksums
checked before it is decoded. Fields the toolkit does not honour (distortion,
another camera model or depth scale, a newer format) are refused rather than
ignored. Every failure is a `DatasetError` naming the file and the field.
"""

from __future__ import annotations

import io
import json
import math
import os
import struct
import unicodedata
import zlib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from PIL import Image

from common.provenance import config_from_record
from render.camera import SENSOR_WIDTH_MM, UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, opencv_to_opengl, validate_pose, viewpoint_to_c2w

DEPTH_SCALE = 0.001
"""Metres per unit of the uint16 depth PNGs."""
FORMAT_VERSION = 1
"""The `nbv.version` this reader understands (and the writer writes)."""
MAX_SIDE = 16384
"""Largest image width or height accepted, pixels."""
MAX_PIXELS = 50_000_000
"""Largest image area accepted (below PIL's decompression-bomb warning)."""
MAX_JSON_BYTES = 256 * 2**20
"""Largest `transforms.json` read."""
MAX_COORD_M = 1e6
"""Largest absolute camera or centre coordinate accepted, metres."""
PINHOLE_MODELS = ("OPENCV", "PINHOLE", "SIMPLE_PINHOLE")
"""nerfstudio camera models read as a pinhole (with zero distortion)."""
DISTORTION_KEYS = ("k1", "k2", "k3", "k4", "p1", "p2")
"""nerfstudio distortion coefficients; all must be 0."""
FOCAL_RTOL = 1e-4
"""Relative tolerance between `fl_x` and `nbv.focal_mm * w / 36`."""
VIEWPOINT_RTOL = 1e-4
"""Tolerance between a recorded viewpoint's position and its pose, relative to max(1, R)."""
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}
"""Samples per pixel of each PNG colour type."""
_ADAM7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2))
"""The seven passes of an interlaced PNG: (x0, y0, dx, dy)."""
_APNG_CHUNKS = (b"acTL", b"fcTL", b"fdAT")
"""Chunks only an animated PNG holds."""


class DatasetError(ValueError):
    """A dataset on disk is missing, corrupt or inconsistent; the message names the file and field."""


class StrictJSONError(ValueError):
    """A document that parses only by a lenient reader: a key twice in one object, or a bare NaN or
    Infinity token (not JSON; strict readers refuse it)."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """An object's pairs as a dict, refusing a key that appears twice (readers disagree on which wins)."""
    doc: dict[str, Any] = {}
    for key, value in pairs:
        if key in doc:
            raise StrictJSONError(f"key {key!r} appears twice in one object (readers disagree on which "
                                  f"one wins); keep one")
        doc[key] = value
    return doc


class _BareToken:
    """Stands where the text held a bare NaN, Infinity or -Infinity, so its field can be named."""

    def __init__(self, token: str) -> None:
        self.token = token


def _bare_token_field(doc: Any) -> tuple[str, str] | None:
    """(field path, token) of the first `_BareToken` in document order, None when there is none."""
    stack: list[tuple[str, Any]] = [("", doc)]
    while stack:
        where, node = stack.pop()
        if isinstance(node, _BareToken):
            return where, node.token
        if isinstance(node, dict):
            stack.extend((f"{where}.{k}" if where else str(k), v) for k, v in reversed(node.items()))
        elif isinstance(node, list):
            stack.extend((f"{where}[{i}]", v) for i, v in reversed(list(enumerate(node))))
    return None


def strict_json_loads(text: str) -> Any:
    """`json.loads` refusing duplicate keys and bare NaN / Infinity / -Infinity (StrictJSONError naming
    the field)."""
    doc = json.loads(text, object_pairs_hook=_unique_keys, parse_constant=_BareToken)
    found = _bare_token_field(doc)
    if found is not None:
        field, token = found
        raise StrictJSONError(f"field {field or '(top level)'} is a bare {token} token, which is not JSON "
                              f"(strict readers refuse it); write a finite number")
    return doc


def read_document(doc_path: Path) -> dict[str, Any]:
    """The parsed `transforms.json` object (strict JSON: no duplicate keys, no NaN or Infinity)."""
    if not doc_path.is_file():
        raise DatasetError(f"{doc_path}: not found (is {doc_path.parent} a view dataset?)")
    if doc_path.stat().st_size > MAX_JSON_BYTES:
        raise DatasetError(f"{doc_path}: larger than {MAX_JSON_BYTES} bytes")
    try:
        doc = strict_json_loads(doc_path.read_text(encoding="utf-8"))
    except StrictJSONError as err:
        raise DatasetError(f"{doc_path}: {err}") from err
    except RecursionError as err:
        raise DatasetError(f"{doc_path}: corrupt JSON: nested too deeply") from err
    except (OSError, ValueError) as err:  # JSONDecodeError, UnicodeDecodeError and the int digit limit
        raise DatasetError(f"{doc_path}: corrupt JSON: {err}") from err
    if not isinstance(doc, dict):
        raise DatasetError(f"{doc_path}: top level must be an object")
    return doc


def typed_field(obj: dict, key: str, kind: type | tuple[type, ...], where: Path, prefix: str = "") -> Any:
    """`obj[key]`, which must be present and of type `kind` (never a bool for numbers)."""
    if key not in obj:
        raise DatasetError(f"{where}: field {prefix}{key} is missing")
    value = obj[key]
    if not isinstance(value, kind) or isinstance(value, bool):
        raise DatasetError(f"{where}: field {prefix}{key} has the wrong type ({type(value).__name__})")
    return value


def to_float(value: Any, where: Path, name: str, lo: float = -math.inf, hi: float = math.inf) -> float:
    """A JSON number as a finite float in [lo, hi]; strings, bools, nulls and overflows refused."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DatasetError(f"{where}: field {name} must be a number, got {type(value).__name__}")
    try:
        number = float(value)
    except OverflowError as err:
        raise DatasetError(f"{where}: field {name} is too large ({err})") from err
    if not math.isfinite(number):
        raise DatasetError(f"{where}: field {name} is NaN or infinite ({number})")
    if not lo <= number <= hi:
        raise DatasetError(f"{where}: field {name} must lie in [{lo:g}, {hi:g}], got {number:g}")
    return number


def number_field(obj: dict, key: str, where: Path, lo: float = -math.inf) -> float:
    """`obj[key]`, which must be present and a finite number of at least `lo`."""
    return to_float(typed_field(obj, key, (int, float), where), where, key, lo)


def number_list(value: Any, length: int, where: Path, name: str, bound: float = math.inf) -> list[float]:
    """A JSON list of `length` finite numbers of magnitude at most `bound`."""
    if not isinstance(value, list) or len(value) != length:
        raise DatasetError(f"{where}: field {name} must be a list of {length} numbers")
    return [to_float(v, where, f"{name}[{i}]", -bound, bound) for i, v in enumerate(value)]


def object_field(obj: dict, key: str, where: Path, prefix: str = "") -> dict[str, Any]:
    """`obj[key]` when it is an object, {} when absent."""
    value = obj.get(key, {})
    if not isinstance(value, dict):
        raise DatasetError(f"{where}: field {prefix}{key} must be an object, got {type(value).__name__}")
    return value


def read_camera(doc: dict, nbv: dict, where: Path) -> UAVCamera:
    """The pinhole camera of `transforms.json`, refusing fields it cannot honour."""
    w, h = typed_field(doc, "w", int, where), typed_field(doc, "h", int, where)
    for key, size in (("w", w), ("h", h)):
        if not 1 <= size <= MAX_SIDE:
            raise DatasetError(f"{where}: field {key} must lie in [1, {MAX_SIDE}], got {size}")
    if w * h > MAX_PIXELS:
        raise DatasetError(f"{where}: fields w, h give {w * h} pixels, more than {MAX_PIXELS}")
    model = doc.get("camera_model", "OPENCV")
    if model not in PINHOLE_MODELS:
        raise DatasetError(f"{where}: field camera_model {model!r} is not supported; "
                           f"use one of {', '.join(PINHOLE_MODELS)} without distortion")
    for key in DISTORTION_KEYS:
        if key in doc and to_float(doc[key], where, key) != 0.0:
            raise DatasetError(f"{where}: field {key} is {doc[key]}; distortion is not supported")
    if "depth_unit_scale_factor" in doc:
        scale = to_float(doc["depth_unit_scale_factor"], where, "depth_unit_scale_factor")
        if not math.isclose(scale, DEPTH_SCALE, rel_tol=1e-9):
            raise DatasetError(f"{where}: field depth_unit_scale_factor is {scale}; only {DEPTH_SCALE} "
                               f"(millimetre depth PNGs) is supported")
    fl_x = number_field(doc, "fl_x", where, 1e-9)
    if not math.isclose(number_field(doc, "fl_y", where), fl_x, rel_tol=1e-6):
        raise DatasetError(f"{where}: fields fl_x and fl_y differ; the UAV camera has square pixels")
    for key, size in (("cx", w), ("cy", h)):
        value = number_field(doc, key, where)
        if not math.isclose(value, size / 2.0, abs_tol=1e-3):
            raise DatasetError(f"{where}: field {key} is off-centre; the UAV camera is centred")
    version = nbv.get("version", FORMAT_VERSION)
    if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= FORMAT_VERSION:
        raise DatasetError(f"{where}: field nbv.version is {version!r}; this reader understands "
                           f"version {FORMAT_VERSION} (is the toolkit older than the dataset?)")
    focal_mm = fl_x * SENSOR_WIDTH_MM / w
    if "focal_mm" in nbv:
        focal_mm = to_float(nbv["focal_mm"], where, "nbv.focal_mm", 1e-9)
        if not math.isclose(fl_x, focal_mm * w / SENSOR_WIDTH_MM, rel_tol=FOCAL_RTOL):
            raise DatasetError(f"{where}: fields fl_x ({fl_x:g}) and nbv.focal_mm ({focal_mm:g}) disagree: "
                               f"expected fl_x = focal_mm * w / {SENSOR_WIDTH_MM:g}")
    near = to_float(nbv.get("near_m", 0.05), where, "nbv.near_m", 1e-9, MAX_COORD_M)
    far = to_float(nbv.get("far_m", 10.0), where, "nbv.far_m", 1e-9, MAX_COORD_M)
    try:
        return UAVCamera(w, h, focal_mm, near, far)
    except ValueError as err:
        raise DatasetError(f"{where}: camera fields: {err}") from err


def read_center(nbv: dict, where: Path) -> np.ndarray:
    """`nbv.center`: three finite coordinates (the origin when absent)."""
    return np.array(number_list(nbv.get("center", [0.0, 0.0, 0.0]), 3, where, "nbv.center", MAX_COORD_M))


def read_render_settings(nbv: dict, where: Path) -> RenderSettings | None:
    """`nbv.render`: the settings the views were rendered with, or None where none are recorded.

    Fields an older writer did not know take their defaults (which reproduce its renders); an unknown
    field, a bad value or a wrong type is refused, naming it."""
    if "render" not in nbv:
        return None
    record = nbv["render"]
    if not isinstance(record, dict):
        raise DatasetError(f"{where}: field nbv.render must be an object, got {type(record).__name__}")
    try:
        return config_from_record(RenderSettings, record)
    except (TypeError, ValueError) as err:
        raise DatasetError(f"{where}: field nbv.render: {err}") from err


def check_name(value: str, where: Path, name: str) -> str:
    """`value` when it is a file name that every tool can write and read back: valid UTF-8 (no lone
    surrogate) without control characters (a newline would split a COLMAP or CSV line)."""
    bad = next((c for c in value if unicodedata.category(c) in ("Cc", "Cs")), None)
    if bad is not None:
        kind = "a lone surrogate" if unicodedata.category(bad) == "Cs" else "a control character"
        raise DatasetError(f"{where}: field {name} contains {kind} ({ascii(bad)}) in {ascii(value)}; "
                           f"rename the file with printable UTF-8 characters")
    return value


def contained_file(root: Path, value: str, where: Path, name: str) -> Path:
    """`root / value`, an existing regular file that stays inside `root` (symlinks resolved)."""
    if "\0" in value or not value or Path(value).is_absolute():
        raise DatasetError(f"{where}: field {name} must be a relative path inside the dataset, got {value!r}")
    path = root / check_name(value, where, name)
    try:
        inside = path.resolve().is_relative_to(root.resolve())
        exists = path.is_file()
    except (OSError, RuntimeError) as err:
        raise DatasetError(f"{where}: field {name}: cannot resolve {value!r} ({err})") from err
    if not inside:
        raise DatasetError(f"{where}: field {name} leaves the dataset folder: {value!r}")
    if not exists:
        raise DatasetError(f"{where}: {name} names a missing file {path}")
    return path


def read_pose(frame: dict, where: Path, prefix: str) -> np.ndarray:
    """The frame's OpenGL `transform_matrix` as a checked OpenCV camera-to-world."""
    name = f"{prefix}transform_matrix"
    rows = typed_field(frame, "transform_matrix", list, where, prefix)
    if len(rows) != 4:
        raise DatasetError(f"{where}: field {name} must be 4x4, got {len(rows)} rows")
    matrix = np.array([number_list(row, 4, where, f"{name}[{i}]", MAX_COORD_M) for i, row in enumerate(rows)])
    try:
        c2w = validate_pose(opencv_to_opengl(matrix), name)
    except ValueError as err:
        raise DatasetError(f"{where}: {err}") from err
    return c2w


def read_viewpoint(meta: dict, c2w: np.ndarray, center: np.ndarray, where: Path,
                   prefix: str) -> Viewpoint | None:
    """The frame's recorded `nbv.viewpoint`, which must agree with its pose; None when absent."""
    if "viewpoint" not in meta:
        return None
    name = f"{prefix}nbv.viewpoint"
    values = number_list(meta["viewpoint"], 3, where, name)
    try:
        view = Viewpoint(*values)
    except ValueError as err:
        raise DatasetError(f"{where}: field {name}: {err}") from err
    offset = np.linalg.norm(viewpoint_to_c2w(view, center)[:3, 3] - c2w[:3, 3])
    if offset > VIEWPOINT_RTOL * max(1.0, view.radius):
        raise DatasetError(f"{where}: field {name} puts the camera {offset:.3g} m from its transform_matrix")
    return view


def check_shared_images(frames: Iterable[tuple[str, str, np.ndarray]], where: Path) -> None:
    """Refuse two frames naming one image (or depth) file with different poses; `frames`: each frame's
    (file_path, depth_file_path, camera-to-world), in order. Identical repeated frames pass."""
    seen: dict[str, tuple[int, np.ndarray]] = {}
    for i, (rgb, depth, c2w) in enumerate(frames):
        for key, value in (("file_path", rgb), ("depth_file_path", depth)):
            first, pose = seen.setdefault(os.path.normpath(value), (i, c2w))
            if first != i and not np.allclose(pose, c2w, rtol=0.0, atol=1e-9):
                raise DatasetError(f"{where}: frames[{first}] and frames[{i}] name the same file {value!r} "
                                   f"({key}) with different poses; give each view its own image")


def png_data_size(width: int, height: int, bits: int, colour: int, interlaced: bool) -> int:
    """Bytes of a PNG's filtered image data (a filter byte per row of each pass), from its header.

    Example:
        >>> png_data_size(64, 48, 8, 2, False)
        9264
    """
    channels = _PNG_CHANNELS.get(colour, 1)

    def rows(w: int, h: int) -> int:
        return 0 if w == 0 else h * (1 + (w * channels * bits + 7) // 8)
    if not interlaced:
        return rows(width, height)
    return sum(rows(max(0, -(-(width - x0) // dx)), max(0, -(-(height - y0) // dy)))
               for x0, y0, dx, dy in _ADAM7)


def check_png_rows(idat: bytes, header: tuple[int, int, int, int, int], path: Path) -> None:
    """Refuse PNG image data (`idat`, the IDAT chunks joined) that inflates to fewer bytes than its
    header's rows need: decoders fill the missing rows with black and say nothing."""
    width, height, bits, colour, interlace = header
    expected = png_data_size(width, height, bits, colour, interlace == 1)
    try:
        size = len(zlib.decompressobj().decompress(idat, expected + 1))
    except zlib.error as err:
        raise DatasetError(f"{path}: corrupt PNG image data ({err})") from err
    if size < expected:
        raise DatasetError(f"{path}: truncated PNG image data: {size} of the {expected} bytes its "
                           f"{width}x{height} header needs (rows missing); re-save the image")


def _png_chunks(data: bytes, path: Path) -> tuple[tuple[int, int, int, int, int], bytes]:
    """(width, height, bit depth, colour type, interlace method) and the joined IDAT data of a complete,
    still PNG whose every chunk CRC is right."""
    if not data.startswith(_PNG_SIGNATURE):
        raise DatasetError(f"{path}: not a PNG file")
    pos, header, idat = len(_PNG_SIGNATURE), None, []
    while True:
        if pos + 12 > len(data):
            raise DatasetError(f"{path}: truncated PNG (no IEND chunk)")
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        end = pos + 12 + length
        if end > len(data):
            raise DatasetError(f"{path}: truncated PNG chunk {kind!r}")
        body = data[pos + 8:end - 4]
        if zlib.crc32(kind + body) != struct.unpack(">I", data[end - 4:end])[0]:
            raise DatasetError(f"{path}: corrupt PNG (bad CRC in chunk {kind!r})")
        if header is None:
            if kind != b"IHDR" or length != 13:
                raise DatasetError(f"{path}: corrupt PNG (first chunk is not IHDR)")
            header = struct.unpack(">IIBBBBB", body)
        if kind in _APNG_CHUNKS:
            raise DatasetError(f"{path}: animated PNG (APNG, chunk {kind.decode()}) is not supported; "
                               f"save one still image")
        if kind == b"IDAT":
            idat.append(body)
        if kind == b"IEND":
            return header[:4] + header[6:], b"".join(idat)
        pos = end


def image_bytes(path: Path, width: int, height: int) -> bytes:
    """The bytes of the image file at `path`, refused (DatasetError) unread when larger than a
    `width` x `height` image can be (8 bytes a pixel + 1 MiB), so a stray huge file is never loaded."""
    limit = 8 * width * height + 2**20
    try:
        if not path.is_file():  # a FIFO or device would block or never end
            raise DatasetError(f"{path}: not a regular file")
        if path.stat().st_size > limit:
            raise DatasetError(f"{path}: file larger than {limit} bytes for a {width}x{height} image")
        with open(path, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as err:
        raise DatasetError(f"{path}: cannot read image: {err}") from err
    if len(data) > limit:  # the file grew after the size check
        raise DatasetError(f"{path}: file larger than {limit} bytes for a {width}x{height} image")
    return data


def read_png(path: Path, width: int, height: int, depth: bool) -> np.ndarray:
    """Decode the PNG at `path` once its size, format and checksums are checked.

    RGB: H x W x 3 uint8 (8-bit or palette PNG). Depth: H x W uint16 (16-bit gray PNG).
    """
    data = image_bytes(path, width, height)
    header, idat = _png_chunks(data, path)
    w, h, bits, colour, _ = header
    if (w, h) != (width, height):
        raise DatasetError(f"{path}: image is {w}x{h}, transforms.json says w={width}, h={height}")
    if depth and (bits, colour) != (16, 0):
        raise DatasetError(f"{path}: depth must be single-channel uint16 (16-bit gray PNG), "
                           f"got bit depth {bits}, colour type {colour}")
    if not depth and bits > 8:
        raise DatasetError(f"{path}: RGB image must have 8-bit channels, got bit depth {bits}")
    check_png_rows(idat, header, path)
    try:
        if depth:
            image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
        else:
            with Image.open(io.BytesIO(data)) as img:
                image = np.asarray(img.convert("RGB"))
    except (OSError, ValueError, SyntaxError, cv2.error, Image.DecompressionBombError, zlib.error) as err:
        raise DatasetError(f"{path}: cannot decode image: {err}") from err
    expected = (height, width) if depth else (height, width, 3)
    if image is None or image.shape != expected or image.dtype != (np.uint16 if depth else np.uint8):
        got = "nothing" if image is None else f"{image.dtype} {image.shape}"
        raise DatasetError(f"{path}: cannot decode image as {expected}, got {got}")
    return image
