"""Dataset reader against hostile input: the probe's findings (D1-D7, S1-S11) and a seeded fuzzer.

Every case ends in a `DatasetError` (a ValueError) whose message names the dataset's file, or in a
dataset whose every frame, pose and centre reads back valid; never another exception.
"""

from __future__ import annotations

import json
import math
import shutil
import struct
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from PIL import Image

from common.io import current_umask
from render.camera import UAVCamera
from render.dataset import DatasetError, DatasetWriter, read_dataset
from render.viewpoint import Viewpoint, viewpoint_to_c2w

SIZE = (32, 24)
CENTER = [0.0, 0.0, 0.4]
CASES = 600


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small valid dataset: 3 views at 32x24."""
    root = tmp_path_factory.mktemp("base") / "ds"
    rng = np.random.default_rng(0)
    with DatasetWriter(root, UAVCamera(*SIZE), {"scene": "synthetic", "center": CENTER}) as writer:
        for i in range(3):
            view = Viewpoint(2.0, float(i), 0.3)
            depth = rng.uniform(1.0, 3.0, SIZE[::-1]).astype(np.float32)
            writer.add(rng.integers(0, 256, (*SIZE[::-1], 3), dtype=np.uint8), depth,
                       viewpoint_to_c2w(view, np.array(CENTER)), view)
    return root


def _copy(base: Path, dest: Path) -> Path:
    shutil.copytree(base, dest, symlinks=True)
    return dest


def _edit(root: Path, change) -> None:
    path = root / "transforms.json"
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def _read_all(root: Path) -> None:
    """Everything refine and reconstruct touch before their real work."""
    ds = read_dataset(root)
    assert np.all(np.isfinite(ds.poses())) and ds.center.shape == (3,)
    for i in range(len(ds)):
        assert ds.rgb(i).shape == (ds.camera.height, ds.camera.width, 3)
        assert ds.depth(i).shape == (ds.camera.height, ds.camera.width)


def _png_with_header(path: Path, width: int, height: int, bits: int, colour: int) -> None:
    """A PNG whose IHDR claims `width` x `height` (CRC correct), with a tiny IDAT and an IEND."""
    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    header = struct.pack(">IIBBBBB", width, height, bits, colour, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(b"\0" * 64))
                     + chunk(b"IEND", b""))


def _set(path: str, value):
    """A change setting doc[...path...] = value (path: dot-separated keys and list indices)."""
    keys = [int(k) if k.isdigit() else k for k in path.split(".")]

    def change(doc):
        node = doc
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
    return change


def _deep(depth: int) -> str:
    return "[" * depth + "]" * depth


PROBE_CASES = {
    "D1_nbv_not_object": (_set("nbv", None), "field nbv must be an object"),
    "D2_frame_nbv_none": (_set("frames.1.nbv", None), r"frames\[1\]\.nbv must be an object"),
    "frames_empty": (_set("frames", []), "field frames is empty"),
    "D2_frame_nbv_list": (_set("frames.1.nbv", ["a"]), r"frames\[1\]\.nbv must be an object"),
    "D3_w_beyond_float": (_set("w", 10**400), "field w must lie in"),
    "D3_fl_x_beyond_float": (_set("fl_x", 10**400), "field fl_x is too large"),
    "D3_center_beyond_float": (_set("nbv.center", [10**400, 0, 0]), r"nbv.center\[0\] is too large"),
    "D3_matrix_beyond_float": (_set("frames.0.transform_matrix.0.3", 10**400), "too large"),
    "D5_object_in_matrix": (_set("frames.0.transform_matrix.3.0", {}),
                            r"transform_matrix\[3\]\[0\] must be a number"),
    "D6_center_object": (_set("nbv.center", {}), "nbv.center must be a list of 3 numbers"),
    "D6_center_two_numbers": (_set("nbv.center", [0, 0]), "nbv.center must be a list of 3 numbers"),
    "D6_center_string": (_set("nbv.center", "abc"), "nbv.center must be a list of 3 numbers"),
    "S1_depth_scale": (_set("depth_unit_scale_factor", 1.0), "depth_unit_scale_factor is 1.0"),
    "S2_fisheye": (_set("camera_model", "OPENCV_FISHEYE"), "camera_model 'OPENCV_FISHEYE' is not supported"),
    "S2_distortion": (_set("k1", 0.3), "field k1 is 0.3; distortion"),
    "S2_distortion_k4": (_set("k4", -0.1), "field k4"),
    "S3_fl_zero": (lambda d: d.update(fl_x=0, fl_y=0), "field fl_x must lie in"),
    "S3_fl_double": (lambda d: d.update(fl_x=d["fl_x"] * 2, fl_y=d["fl_y"] * 2),
                     "fl_x .* nbv.focal_mm .* disagree"),
    "S4_future_version": (_set("nbv.version", 2), "nbv.version is 2"),
    "S6_viewpoint_off_pose": (_set("frames.0.nbv.viewpoint.1", 3.0),
                              r"frames\[0\]\.nbv\.viewpoint puts the camera"),
    "S7_translation_1e30": (_set("frames.2.transform_matrix.0.3", 1e30), r"matrix\[0\]\[3\] must lie"),
    "S7_translation_1e308": (_set("frames.2.transform_matrix.0.3", 1.7e308), "must lie in"),
    "S8_bool_focal": (_set("nbv.focal_mm", True), "nbv.focal_mm must be a number"),
    "S8_string_in_matrix": (_set("frames.0.transform_matrix.0.0", "1"), "must be a number"),
    "S8_string_viewpoint": (_set("frames.0.nbv.viewpoint.0", "2"), "must be a number"),
    "S8_string_near": (_set("nbv.near_m", "0.05"), "nbv.near_m must be a number"),
    "S9_center_nan": (_set("nbv.center", [float("nan"), 0, 0]), r"field nbv.center\[0\] is a bare NaN token"),
    "S9_center_null": (_set("nbv.center", None), "nbv.center must be a list"),
    "S11_frame_nbv_string": (_set("frames.0.nbv", ""), r"frames\[0\]\.nbv must be an object"),
    "S5_absolute_path": (_set("frames.1.file_path", "/etc/passwd"), "must be a relative path inside"),
    "S5_dotdot_path": (_set("frames.1.file_path", "../outside.png"), "leaves the dataset folder"),
    "S5_nul_in_path": (_set("frames.1.file_path", "images/0000.png\0x"), "must be a relative path"),
}


@pytest.mark.parametrize("name", sorted(PROBE_CASES))
def test_probe_findings_are_named_errors(base, tmp_path, name):
    change, message = PROBE_CASES[name]
    root = _copy(base, tmp_path / "ds")
    Image.fromarray(np.zeros((SIZE[1], SIZE[0], 3), np.uint8)).save(tmp_path / "outside.png")
    _edit(root, change)
    with pytest.raises(DatasetError, match=message) as err:
        _read_all(root)
    assert "transforms.json" in str(err.value)


def test_d4_deeply_nested_json_is_a_named_error(base, tmp_path):
    root = _copy(base, tmp_path / "ds")
    path = root / "transforms.json"
    path.write_text(path.read_text().replace('"frames": [', f'"x": {_deep(100_000)}, "frames": [', 1))
    with pytest.raises(DatasetError, match="transforms.json: corrupt JSON: nested too deeply"):
        read_dataset(root)


@pytest.mark.parametrize("folder, bits, colour", [("images", 8, 2), ("depth", 16, 0)])
def test_d7_bomb_header_is_refused_before_decoding(base, tmp_path, folder, bits, colour):
    root = _copy(base, tmp_path / "ds")
    _png_with_header(root / folder / "0000.png", 100_000, 100_000, bits, colour)
    ds = read_dataset(root)
    with pytest.raises(DatasetError, match=f"{folder}/0000.png: image is 100000x100000"):
        ds.rgb(0) if folder == "images" else ds.depth(0)


def test_s5_symlink_leaving_the_folder_is_refused(base, tmp_path):
    root = _copy(base, tmp_path / "ds")
    outside = tmp_path / "outside.png"
    shutil.copy(root / "images" / "0001.png", outside)
    (root / "images" / "0001.png").unlink()
    (root / "images" / "0001.png").symlink_to(outside)
    with pytest.raises(DatasetError, match=r"frames\[1\]\.file_path leaves the dataset folder"):
        read_dataset(root)


@pytest.mark.parametrize("kind", ["rgb16", "jpeg", "depth_as_rgb", "missing_iend", "bad_crc"])
def test_s10_images_that_are_not_what_they_claim_are_refused(base, tmp_path, kind):
    root = _copy(base, tmp_path / "ds")
    target = root / "images" / "0001.png"
    if kind == "rgb16":
        cv2.imwrite(str(target), np.zeros((SIZE[1], SIZE[0], 3), np.uint16))
    elif kind == "jpeg":
        Image.fromarray(np.zeros((SIZE[1], SIZE[0], 3), np.uint8)).save(target, format="JPEG")
    elif kind == "depth_as_rgb":
        _edit(root, _set("frames.1.file_path", "depth/0001.png"))
        target = root / "depth" / "0001.png"
    elif kind == "missing_iend":
        target.write_bytes(target.read_bytes()[:-12])
    else:
        data = bytearray(target.read_bytes())
        data[40] ^= 0xFF
        target.write_bytes(bytes(data))
    with pytest.raises(DatasetError, match=f"{target.parent.name}/0001.png"):
        read_dataset(root).rgb(1)


def _text_edit(root: Path, old: str, new: str) -> None:
    path = root / "transforms.json"
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


@pytest.mark.parametrize("old, new, key", [
    ('"w": 32', '"w": 16, "w": 32', "'w'"),
    ('"frames": [', '"frames": [], "frames": [', "'frames'"),
    ('"fl_x": ', '"fl_x": 1000.0, "fl_x": ', "'fl_x'")])
def test_duplicate_json_key_refused(base, tmp_path, old, new, key):
    root = _copy(base, tmp_path / "ds")
    _text_edit(root, old, new)
    with pytest.raises(DatasetError, match=f"transforms.json: key {key} appears twice in one object"):
        read_dataset(root)


@pytest.mark.parametrize("token", ["NaN", "Infinity", "-Infinity"])
def test_bare_nan_token_refused_anywhere(base, tmp_path, token):
    root = _copy(base, tmp_path / "ds")
    _text_edit(root, '"nbv": {', f'"aabb_scale": {token}, "nbv": {{"extra": [{token}], ')
    message = rf"transforms.json: field frames\[0\]\.aabb_scale is a bare {token} token, which is not JSON"
    with pytest.raises(DatasetError, match=message):
        read_dataset(root)


def test_dataset_writer_never_writes_nan(tmp_path):
    """A NaN or infinity reaching transforms.json (here a frame's own field) is refused, not written as a
    bare token: the reader refuses those, and so do strict parsers elsewhere."""
    camera = UAVCamera(*SIZE)
    view = Viewpoint(2.0, 0.0, 0.3)
    with pytest.raises(ValueError, match="transforms.json: cannot write a NaN or infinite number as JSON"):
        with DatasetWriter(tmp_path / "ds", camera, {"center": CENTER}) as writer:
            writer.add(np.zeros((SIZE[1], SIZE[0], 3), np.uint8), np.ones(SIZE[::-1], np.float32),
                       viewpoint_to_c2w(view, np.array(CENTER)), view, {"extra": -math.inf})
    assert not (tmp_path / "ds").exists()


def _png_chunks_of(data: bytes) -> list[tuple[bytes, bytes]]:
    chunks, pos = [], 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunks.append((kind, data[pos + 8:pos + 8 + length]))
        pos += 12 + length
    return chunks


def _png_of(chunks: list[tuple[bytes, bytes]]) -> bytes:
    return b"\x89PNG\r\n\x1a\n" + b"".join(struct.pack(">I", len(body)) + kind + body
                                          + struct.pack(">I", zlib.crc32(kind + body))
                                          for kind, body in chunks)


@pytest.mark.parametrize("folder, row_bytes", [("images", SIZE[0] * 3 + 1), ("depth", SIZE[0] * 2 + 1)])
def test_png_with_short_image_data_refused(base, tmp_path, folder, row_bytes):
    root = _copy(base, tmp_path / "ds")
    path = root / folder / "0001.png"
    chunks = _png_chunks_of(path.read_bytes())
    raw = zlib.decompress(b"".join(body for kind, body in chunks if kind == b"IDAT"))
    assert len(raw) == SIZE[1] * row_bytes  # the hand-worked size: a filter byte per row
    half = zlib.compress(raw[:row_bytes * SIZE[1] // 2])  # a valid stream holding the first 12 rows
    path.write_bytes(_png_of([c for c in chunks if c[0] not in (b"IDAT", b"IEND")]
                             + [(b"IDAT", half), (b"IEND", b"")]))
    ds = read_dataset(root)
    with pytest.raises(DatasetError, match=f"{folder}/0001.png: truncated PNG image data: "
                                           f"{row_bytes * 12} of the {row_bytes * 24} bytes"):
        ds.rgb(1) if folder == "images" else ds.depth(1)


def test_interlaced_png_reads_back(base, tmp_path):
    """An Adam7 PNG written by hand (seven passes, filter 0 on every row) is read whole."""
    root = _copy(base, tmp_path / "ds")
    image = read_dataset(root).rgb(2)
    adam7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2))
    passes = [image[y0::dy, x0::dx] for x0, y0, dx, dy in adam7]
    raw = b"".join(b"\0" + row.tobytes() for rows in passes if rows.shape[1] for row in rows)
    header = struct.pack(">IIBBBBB", SIZE[0], SIZE[1], 8, 2, 0, 0, 1)
    (root / "images" / "0002.png").write_bytes(_png_of([(b"IHDR", header), (b"IDAT", zlib.compress(raw)),
                                                        (b"IEND", b"")]))
    assert np.array_equal(read_dataset(root).rgb(2), image)


def test_frames_sharing_an_image_with_different_poses_refused(base, tmp_path):
    root = _copy(base, tmp_path / "ds")
    _edit(root, lambda doc: doc["frames"].append(dict(doc["frames"][0])))  # an identical repeat passes
    assert len(read_dataset(root)) == 4
    _edit(root, lambda doc: doc["frames"][1].update(file_path="images/0000.png",
                                                    depth_file_path="depth/0000.png"))
    with pytest.raises(DatasetError, match=r"frames\[0\] and frames\[1\] name the same file .*0000.png"
                                           r".*with different poses"):
        read_dataset(root)


def test_animated_png_refused(base, tmp_path):
    root = _copy(base, tmp_path / "ds")
    path = root / "images" / "0000.png"
    still = Image.open(path).convert("RGB")
    still.save(path, save_all=True, append_images=[Image.new("RGB", still.size)], default_image=True)
    assert b"acTL" in path.read_bytes()
    with pytest.raises(DatasetError, match="0000.png: animated PNG .APNG, chunk acTL. is not supported"):
        read_dataset(root).rgb(0)


def test_lone_surrogate_in_file_path_refused(base, tmp_path):
    root = _copy(base, tmp_path / "ds")
    _text_edit(root, '"images/0001.png"', '"images/0001\\ud800.png"')
    with pytest.raises(DatasetError, match=r"frames\[1\]\.file_path contains a lone surrogate"):
        read_dataset(root)


@pytest.mark.parametrize("char", ["\n", "\r", "\t", "\x1b", "\x85"])
def test_control_character_in_image_name_refused(base, tmp_path, char):
    root = _copy(base, tmp_path / "ds")
    name = f"images/00{char}02.png"
    (root / "images" / "0002.png").rename(root / name)
    _edit(root, _set("frames.2.file_path", name))
    with pytest.raises(DatasetError, match=r"frames\[2\]\.file_path contains a control character"):
        read_dataset(root)


def test_dataset_folders_follow_the_umask(base):
    assert base.stat().st_mode & 0o777 == 0o777 & ~current_umask()


def _mutate_json(doc: dict, rng: np.random.Generator, outside: Path) -> None:
    """Replace, delete or duplicate one random node of the document."""
    paths = []

    def walk(node, path):
        paths.append(path)
        items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
        for key, child in items:
            walk(child, (*path, key))
    walk(doc, ())
    path = paths[int(rng.integers(1, len(paths)))]
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    values = [None, True, False, 0, -1, 1, 2, 0.5, -1e-320, 1e308, -1e308, 10**400, -(10**30), float("nan"),
              float("inf"), float("-inf"), "", "1", "abc", "NaN", [], {}, [[]], [1, 2, 3], [0] * 16, {"a": 1},
              "../outside.png", str(outside), "images/../../outside.png", "images", "/dev/null",
              "depth/0000.png", "images/0000.png", "x" * 5000, "OPENCV_FISHEYE", "PINHOLE",
              [[1, 0, 0, 0]] * 4]
    action = rng.integers(3)
    if action == 0 and isinstance(parent, dict):
        del parent[path[-1]]
    elif action == 1 and isinstance(parent, list):
        parent.append(parent[path[-1]])
    else:
        parent[path[-1]] = values[int(rng.integers(len(values)))]


def _mutate_text(root: Path, rng: np.random.Generator) -> None:
    """Damage transforms.json as text: deep nesting, truncation, a flipped byte, another encoding, a key
    twice, a bare NaN."""
    path = root / "transforms.json"
    data = bytearray(path.read_bytes())
    action, pos = int(rng.integers(6)), int(rng.integers(len(data)))
    if action == 0:
        key = data.index(b'"frames": [') if rng.integers(2) else data.index(b'"nbv": {')
        nested = _deep(int(rng.choice([900, 5000, 100_000]))).encode()
        data[key:key] = b'"x": ' + nested + b", "
    elif action == 1:
        del data[pos:]
    elif action == 2:
        data[pos] ^= 1 << int(rng.integers(8))
    elif action == 3:
        data = bytearray(data.decode().encode(["utf-16", "utf-8-sig", "utf-32"][int(rng.integers(3))]))
    else:
        key = [b'"w": ', b'"fl_x": ', b'"frames": ', b'"center": '][int(rng.integers(4))]
        extra = b"NaN, " if action == 4 else [b"-Infinity, ", b"Infinity, "][int(rng.integers(2))]
        data = data.replace(key, key + extra + key, 1)
    path.write_bytes(bytes(data))


def _mutate_png(root: Path, rng: np.random.Generator) -> None:
    """Damage one image or depth file: truncation, byte flips, a lying header, another format."""
    folder = ["images", "depth"][int(rng.integers(2))]
    path = root / folder / f"{int(rng.integers(3)):04d}.png"
    data = bytearray(path.read_bytes())
    action = int(rng.integers(9))
    if action == 0:
        path.write_bytes(bytes(data[:int(rng.integers(len(data)))]))
    elif action in (7, 8):  # image data short of its rows (valid stream and CRCs), or an APNG chunk
        chunks = _png_chunks_of(bytes(data))
        raw = zlib.decompress(b"".join(body for kind, body in chunks if kind == b"IDAT"))
        tail = ([(b"IDAT", zlib.compress(raw[:int(rng.integers(len(raw)))]))] if action == 7
                else [(b"acTL", struct.pack(">II", 2, 0))] + [c for c in chunks if c[0] == b"IDAT"])
        path.write_bytes(_png_of([chunks[0], *tail, (b"IEND", b"")]))
    elif action == 1:
        for pos in rng.integers(0, len(data), int(rng.integers(1, 8))):
            data[pos] ^= int(rng.integers(1, 256))
        path.write_bytes(bytes(data))
    elif action == 2:
        side = [1, 33, 100_000, 2**31 - 1, 0][int(rng.integers(5))]
        _png_with_header(path, side, side, [8, 16, 1][int(rng.integers(3))], [0, 2, 6][int(rng.integers(3))])
    elif action == 3:
        Image.fromarray(np.zeros((SIZE[1], SIZE[0], 3), np.uint8)).save(path, format=["JPEG", "BMP", "TIFF"][
            int(rng.integers(3))])
    elif action == 4:
        channels = [1, 3, 4][int(rng.integers(3))]
        image = rng.integers(0, 2**16, (SIZE[1], SIZE[0], channels), dtype=np.uint16)
        cv2.imwrite(str(path), image.squeeze())
    elif action == 5:
        cv2.imwrite(str(path), rng.integers(0, 256, (SIZE[1], SIZE[0]), dtype=np.uint8))
    else:
        path.unlink()
        path.mkdir()


def test_fuzzed_datasets_give_named_errors_or_valid_data(base, tmp_path):
    rng = np.random.default_rng(13)
    outside = tmp_path / "outside.png"
    Image.fromarray(np.zeros((SIZE[1], SIZE[0], 3), np.uint8)).save(outside)
    counts = {"named": 0, "valid": 0}
    for case in range(CASES):
        root = _copy(base, tmp_path / f"case{case}")
        if case % 4 == 3:
            _mutate_png(root, rng)
        elif case % 8 == 2:
            _mutate_text(root, rng)
        else:
            _edit(root, lambda doc: [_mutate_json(doc, rng, outside) for _ in range(int(rng.integers(1, 3)))])
        try:
            _read_all(root)
            counts["valid"] += 1
        except DatasetError as err:  # a ValueError naming the file and field
            assert str(root) in str(err), f"case {case}: error does not name the dataset: {err}"
            counts["named"] += 1
        shutil.rmtree(root)
    print(f"dataset fuzz: {CASES} cases, {counts['named']} named errors, {counts['valid']} valid, 0 other")
    assert counts["named"] + counts["valid"] == CASES and min(counts.values()) > 20
