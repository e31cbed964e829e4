"""Capture readers against hostile input: named corruptions of COLMAP text, binary and nerfstudio captures,
and a seeded fuzzer over their bytes and fields.

Every case ends in a `DatasetError` (a ValueError) whose message names the file at fault, or in a capture
whose every frame decodes and whose kept subset writes and reads back; never another exception.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from foreign_captures import similarity, write_colmap, write_nerfstudio
from PIL import Image
from synthetic import write_circle_dataset

from render.captures.open import read_views, write_kept
from render.dataset import DatasetError, read_dataset

CASES = 40
"""Random mutations per format."""
NAN = b"\0\0\0\0\0\0\xf8\x7f"
"""A little-endian float64 NaN."""


@pytest.fixture(scope="module")
def bases(tmp_path_factory) -> dict[str, Path]:
    """A 4-view capture at 32x24 as COLMAP text, COLMAP binary and nerfstudio JPEG."""
    root = tmp_path_factory.mktemp("bases")
    native = read_dataset(write_circle_dataset(root / "native", [0, 1, 2, 3], size=(32, 24)))
    sim = similarity(0)
    return {"text": write_colmap(native, root / "text", "text", sim, points=6),
            "binary": write_colmap(native, root / "binary", "binary", sim, points=6),
            "nerfstudio": write_nerfstudio(native, root / "ns", sim, coeffs=(0.01, 0.0, 0.0, 0.0))}


def _read_all(root: Path, out: Path) -> None:
    """Everything refine touches: the frames, every image, the kept subset written and read back."""
    capture = read_views(root)
    for i in range(len(capture)):
        assert capture.rgb(i).shape == (capture.camera.height, capture.camera.width, 3)
    write_kept(capture, list(range(0, len(capture), 2)), out, {})
    assert len(read_views(out)) == len(range(0, len(capture), 2))


def _replace(path: Path, old: str, new: str):
    def change(root: Path) -> None:
        text = (root / path).read_text()
        assert old in text, (path, old)
        (root / path).write_text(text.replace(old, new, 1))
    return change


def _bytes(path: Path, edit):
    def change(root: Path) -> None:
        (root / path).write_bytes(edit(bytearray((root / path).read_bytes())))
    return change


def _json(edit):
    def change(root: Path) -> None:
        doc = json.loads((root / "transforms.json").read_text())
        edit(doc)
        (root / "transforms.json").write_text(json.dumps(doc))
    return change


def _nan_token(path: Path) -> None:
    """The first image's QW (line 5 of pycolmap's images.txt) set to nan."""
    lines = path.read_text().splitlines()
    tokens = lines[4].split()
    lines[4] = " ".join([tokens[0], "nan", *tokens[2:]])
    path.write_text("\n".join(lines) + "\n")


def _set_le(offset: int, value: int, size: int):
    def edit(data: bytearray) -> bytearray:
        data[offset:offset + size] = value.to_bytes(size, "little", signed=value < 0)
        return data
    return edit


TXT = BIN = Path("sparse/0")
UNKNOWN, FISHEYE = "unknown camera model 'FOOBAR'", "not supported; undistort"
NAMED = {
    "text": [
        ("missing image", lambda r: (r / "images" / "0001.png").unlink(), "names a missing file"),
        ("no images folder", lambda r: shutil.rmtree(r / "images"), "without an images/ folder"),
        ("bad camera model", _replace(TXT / "cameras.txt", "OPENCV", "FOOBAR"), UNKNOWN),
        ("fisheye model", _replace(TXT / "cameras.txt", "OPENCV", "OPENCV_FISHEYE"), FISHEYE),
        ("NaN pose", lambda r: _nan_token(r / TXT / "images.txt"), "line 5: NaN or infinite"),
        ("missing field", _replace(TXT / "images.txt", " 1 0000.png", " 0000.png"), "expected IMAGE_ID"),
        ("missing camera", _replace(TXT / "images.txt", " 1 0000.png", " 7 0000.png"), "missing camera 7"),
        ("repeated name", _replace(TXT / "images.txt", "0001.png", "0000.png"), "appears twice"),
        ("escaping name", _replace(TXT / "images.txt", "0001.png", "../0001.png"), "leaves the dataset"),
        ("track to nowhere", _replace(TXT / "points3D.txt", "\n1 ", "\n1 0 0 0 1 2 3 0 99 0\n77 "),
         "does not exist"),
        ("not UTF-8", _bytes(TXT / "cameras.txt", lambda d: d + b"\xff\xfe"), "not UTF-8"),
        ("image of another size", lambda r: Image.new("RGB", (8, 8)).save(r / "images" / "0002.png"),
         "image is 8x8"),
    ],
    "binary": [
        ("truncated images", _bytes(BIN / "images.bin", lambda d: d[:100]), "truncated"),
        ("huge image count", _bytes(BIN / "images.bin", _set_le(0, 2**40, 8)), "claims 1099511627776 images"),
        ("bad model id", _bytes(BIN / "cameras.bin", _set_le(12, 999, 4)), "unknown camera model 999"),
        ("fisheye model id", _bytes(BIN / "cameras.bin", _set_le(12, 5, 4)), "OPENCV_FISHEYE, which is not"),
        ("stray bytes", _bytes(BIN / "points3D.bin", lambda d: d + b"\0\0"), "stray bytes"),
        ("NaN pose", _bytes(BIN / "images.bin", lambda d: d[:12] + NAN + d[20:]), "NaN"),
        ("zero quaternion", _bytes(BIN / "images.bin", lambda d: d[:12] + bytes(32) + d[44:]), "zero"),
        ("empty cameras", _bytes(BIN / "cameras.bin", lambda d: d[:0]), "truncated at byte 0"),
    ],
    "nerfstudio": [
        ("unknown file_path", _json(lambda d: d["frames"][1].update(file_path="images/nope.jpg")),
         "names a missing file"),
        ("absolute file_path", _json(lambda d: d["frames"][1].update(file_path="/etc/passwd")),
         "must be a relative path"),
        ("NaN pose", _json(lambda d: d["frames"][2]["transform_matrix"][0].__setitem__(3, float("nan"))),
         "NaN"),
        ("fisheye model", _json(lambda d: d.update(camera_model="OPENCV_FISHEYE")), "is not supported"),
        ("k4", _json(lambda d: d.update(k4=0.1)), "k4 is a fisheye coefficient"),
        ("no focal length", _json(lambda d: d.pop("fl_x")), "field fl_x is missing"),
        ("frames differ in size", _json(lambda d: d["frames"][0].update(w=16)), "differ in image size"),
        ("truncated JPEG", _bytes(Path("images/frame_00002.jpg"), lambda d: d[:200]), "cannot decode JPEG"),
        ("not an image", _bytes(Path("images/frame_00003.jpg"), lambda d: bytearray(b"hello")),
         "not a JPEG or PNG"),
        ("no frames", _json(lambda d: d.update(frames=[])), "field frames is empty"),
    ],
}


@pytest.mark.parametrize(("kind", "case"), [(k, c) for k, cases in NAMED.items() for c in range(len(cases))],
                         ids=[f"{k}-{c[0]}" for k, cases in NAMED.items() for c in cases])
def test_named_corruption_is_a_named_error(bases, kind, case, tmp_path):
    _, change, message = NAMED[kind][case]
    root = shutil.copytree(bases[kind], tmp_path / "capture")
    change(root)
    with pytest.raises(DatasetError, match=message) as err:
        _read_all(root, tmp_path / "out")
    assert str(tmp_path) in str(err.value)  # names the file at fault


def _mutate_bytes(data: bytes, rng: np.random.Generator) -> bytes:
    data = bytearray(data)
    action = rng.integers(4)
    if action == 0 and data:
        data = data[:rng.integers(len(data))]
    elif action == 1 and data:
        for pos in rng.integers(0, len(data), rng.integers(1, 4)):
            data[pos] = rng.integers(256)
    elif action == 2:
        pos = rng.integers(len(data) + 1)
        data[pos:pos] = rng.integers(0, 256, rng.integers(1, 9), dtype=np.uint8).tobytes()
    elif data:
        pos = rng.integers(len(data))
        data[pos:pos + 8] = rng.choice([b"nan", b"-1", b"1e999", b"\xff" * 8, b"\0" * 8, b"99"])
    return bytes(data)


@pytest.mark.parametrize("kind", ["text", "binary", "nerfstudio"])
def test_fuzzed_captures_read_or_fail_by_name(bases, kind, tmp_path):
    rng = np.random.default_rng({"text": 1, "binary": 2, "nerfstudio": 3}[kind])
    files = sorted(p.relative_to(bases[kind]) for p in bases[kind].rglob("*") if p.is_file()
                   and p.suffix in (".txt", ".bin", ".json"))
    outcomes = {"read": 0, "refused": 0}
    for case in range(CASES):
        root = shutil.copytree(bases[kind], tmp_path / f"c{case}")
        target = root / files[rng.integers(len(files))]
        target.write_bytes(_mutate_bytes(target.read_bytes(), rng))
        try:
            _read_all(root, tmp_path / f"o{case}")
            outcomes["read"] += 1
        except DatasetError as err:
            assert str(root) in str(err), err
            outcomes["refused"] += 1
        shutil.rmtree(root)
    assert outcomes["refused"] > CASES // 4, outcomes  # most mutations break something, named
