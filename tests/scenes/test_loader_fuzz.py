"""Mesh loader against hostile input: the probe's findings (M1-M6) and a seeded fuzzer of OBJ and PLY text.

Every case ends in a ValueError or FileNotFoundError whose message names the file, or in a normalised,
finite target; never another exception and never a NumPy warning.
"""

from __future__ import annotations

import io
import os
import struct
import threading
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from scenes.loader import load_file_scene

CASES = 600
BOX_OBJ = """# a 2 x 1 x 3 box with texture coordinates and one stray vertex
mtllib none.mtl
v -1 -0.5 0
v 1 -0.5 0
v 1 0.5 0
v -1 0.5 0
v -1 -0.5 3
v 1 -0.5 3
v 1 0.5 3
v -1 0.5 3
v 1e9 1e9 1e9
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1 3/3 2/2
f 1/1 4/4 3/3
f 5/1 6/2 7/3
f 5/1 7/3 8/4
f 1/1 2/2 6/3
f 1/1 6/3 5/4
f 2/1 3/2 7/3
f 2/1 7/3 6/4
f 3/1 4/2 8/3
f 3/1 8/3 7/4
f 4/1 1/2 5/3
f 4/1 5/3 8/4
"""


def _box_ply() -> str:
    box = trimesh.creation.box((2.0, 1.0, 3.0))
    return trimesh.exchange.ply.export_ply(box, encoding="ascii").decode()


def _check_scene(path: Path) -> None:
    """Load `path`; a loaded target must be finite, indexed in range and normalised."""
    scene = load_file_scene(path, ground=False)
    lo, hi = scene.bounds()
    assert np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))
    assert np.max(hi - lo) == pytest.approx(1.0) and lo[2] == pytest.approx(0.0, abs=1e-9)
    for part in scene.parts:
        assert part.faces.max() < len(part.vertices)
        assert part.uv is None or np.all(np.isfinite(part.uv))


def test_m1_corrupt_embedded_texture_names_the_file(tmp_path, fresh_cache):
    box = trimesh.creation.box((2.0, 1.0, 3.0))
    image = np.random.default_rng(0).integers(0, 256, (64, 64, 3), dtype=np.uint8)
    box.visual = trimesh.visual.TextureVisuals(uv=np.random.default_rng(1).random((len(box.vertices), 2)),
                                               image=Image.fromarray(image))
    glb = bytearray(trimesh.exchange.gltf.export_glb(trimesh.Scene(box)))
    start = glb.index(b"IDAT") + 8
    glb[start:start + 64] = bytes(64)
    path = tmp_path / "badtex.glb"
    path.write_bytes(bytes(glb))
    with pytest.raises(ValueError, match="badtex.glb.*texture"):
        load_file_scene(path)


def test_m2_unreferenced_vertices_do_not_count_for_normalisation(tmp_path):
    box = trimesh.creation.box((2.0, 1.0, 3.0))
    path = tmp_path / "stray.ply"
    trimesh.Trimesh(list(box.vertices) + [[1e9, 1e9, 1e9]], box.faces, process=False).export(path)
    lo, hi = load_file_scene(path, ground=False).bounds()
    assert hi - lo == pytest.approx([2 / 3, 1 / 3, 1.0])


def test_m3_overflowing_extent_is_refused(tmp_path):
    path = tmp_path / "far.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 6\nproperty double x\nproperty double y\n"
                    "property double z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                    "-1.7e308 0 0\n-1.7e308 1 0\n-1.7e308 0 1\n1.7e308 0 0\n1.7e308 1 0\n1.7e308 0 1\n"
                    "3 0 1 2\n3 3 4 5\n")
    with pytest.raises(ValueError, match="far.ply: cannot normalise.*overflow"):
        load_file_scene(path)


def test_m4_zero_area_faces_get_finite_uvs_without_warnings(tmp_path):
    path = tmp_path / "flat.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 1\nv 2 0 0\nf 1 2 3\nf 1 2 4\n")  # the second face has no area
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _check_scene(path)


def test_m5_zero_size_target_names_the_file(tmp_path):
    path = tmp_path / "point.obj"
    path.write_text("v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n")
    with pytest.raises(ValueError, match="point.obj: cannot normalise.*zero size"):
        load_file_scene(path)


def test_m5_nan_node_matrix_names_the_file(tmp_path):
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box((1.0, 1.0, 1.0)), transform=np.full((4, 4), np.nan))
    path = tmp_path / "nan.glb"
    path.write_bytes(trimesh.exchange.gltf.export_glb(scene))
    with pytest.raises(ValueError, match="nan.glb"):
        load_file_scene(path)


@pytest.mark.parametrize("text", [
    "", "garbage", '<scene version="3.0.0"><shape type="nosuchplugin"/></scene>',
    '<scene version="3.0.0"><include filename="missing.xml"/></scene>'])
def test_m6_broken_mitsuba_xml_is_refused_at_load_naming_the_file(tmp_path, text):
    path = tmp_path / "scene.xml"
    path.write_text(text)
    with pytest.raises(ValueError, match="scene.xml: cannot load Mitsuba scene"):
        load_file_scene(path)


_TOKENS = ["nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-1", "1", "4", "9", "99999999999",
           "-99999999999", "x", "", "1/1/1", "0/0", "3.5", "1e400", "2147483648"]


def _mutate(text: str, rng: np.random.Generator) -> str:
    """Replace tokens, drop, duplicate or truncate lines, or insert garbage."""
    lines = text.splitlines()
    for _ in range(int(rng.integers(1, 4))):
        lines = lines or ["#"]
        action = int(rng.integers(5))
        i = int(rng.integers(len(lines)))
        if action == 0:
            words = lines[i].split(" ")
            words[int(rng.integers(len(words)))] = _TOKENS[int(rng.integers(len(_TOKENS)))]
            lines[i] = " ".join(words)
        elif action == 1 and len(lines) > 1:
            del lines[i]
        elif action == 2:
            lines.insert(i, lines[int(rng.integers(len(lines)))])
        elif action == 3:
            lines = lines[:i]
        else:
            lines.insert(i, bytes(rng.integers(32, 127, int(rng.integers(1, 20)), dtype=np.uint8)).decode())
    return "\n".join(lines) + "\n"


def test_fuzzed_meshes_give_named_errors_or_valid_targets(tmp_path, fresh_cache):
    rng = np.random.default_rng(13)
    bases = {".obj": BOX_OBJ, ".ply": _box_ply()}
    counts = {"named": 0, "valid": 0}
    for case in range(CASES):
        suffix = ".obj" if case % 2 else ".ply"
        path = tmp_path / f"case{case}{suffix}"
        path.write_text(_mutate(bases[suffix], rng))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", RuntimeWarning)
                _check_scene(path)
            counts["valid"] += 1
        except (ValueError, FileNotFoundError) as err:
            assert path.name in str(err), f"case {case}: error does not name the file: {err}"
            counts["named"] += 1
    print(f"loader fuzz: {CASES} cases, {counts['named']} named errors, {counts['valid']} valid, 0 other")
    assert counts["named"] + counts["valid"] == CASES and min(counts.values()) > 20


TRIANGLE_OBJ = "v 0 0 0\nv 2 0 0\nv 0 1 3\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"


def _load_within(path: Path, seconds: float = 30.0):
    """`load_file_scene(path)` in a thread: its result or exception, failing the test if it blocks."""
    outcome: dict = {}

    def run():
        try:
            outcome["scene"] = load_file_scene(path, ground=False)
        except Exception as err:  # noqa: BLE001 - handed to the test to judge
            outcome["error"] = err
    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(seconds)
    assert not worker.is_alive(), f"loading {path} blocked for {seconds} s"
    return outcome


@pytest.mark.parametrize("named", ["mtllib", "map_Kd"])
def test_fifo_named_as_mtllib_or_texture_refused_without_blocking(tmp_path, fresh_cache, named):
    os.mkfifo(tmp_path / "fifo")
    mtl = "fifo" if named == "mtllib" else "m.mtl"
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd fifo\n")
    (tmp_path / "model.obj").write_text(f"mtllib {mtl}\nusemtl a\n{TRIANGLE_OBJ}")
    error = _load_within(tmp_path / "model.obj").get("error")
    assert isinstance(error, ValueError) and "model.obj: it names 'fifo', which is not a regular file" in str(
        error), error


def test_oversized_texture_file_refused_unread(tmp_path, fresh_cache):
    with open(tmp_path / "tex.png", "wb") as handle:  # a 2 GB sparse file: nothing written, nothing read
        handle.truncate(2 * 10**9)
    (tmp_path / "m.mtl").write_text("newmtl a\nmap_Kd tex.png\n")
    (tmp_path / "model.obj").write_text(f"mtllib m.mtl\nusemtl a\n{TRIANGLE_OBJ}")
    with pytest.raises(ValueError, match="model.obj: it names 'tex.png' of 2000000000 bytes, more than"):
        load_file_scene(tmp_path / "model.obj")


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl"])
def test_zero_total_area_refused(tmp_path, suffix):
    """The box's 8 corners with every face repeating a vertex: a size, but no area to see."""
    box = trimesh.creation.box((2.0, 1.0, 3.0))
    flat = trimesh.Trimesh(box.vertices, np.stack([box.faces[:, 0], box.faces[:, 0], box.faces[:, 1]], 1),
                           process=False)
    flat.export(tmp_path / f"flat{suffix}")
    with pytest.raises(ValueError, match=f"flat{suffix}: the target mesh has no area"):
        load_file_scene(tmp_path / f"flat{suffix}")


def test_collinear_triangles_refused(tmp_path):
    lines = [f"v {i} {2 * i} {3 * i}" for i in range(102)]
    lines += [f"f {i} {i + 1} {i + 2}" for i in range(1, 101)]
    (tmp_path / "line.obj").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match="line.obj: the target mesh has no area"):
        load_file_scene(tmp_path / "line.obj")


def test_negative_obj_indices_resolved(tmp_path):
    """Relative indices after interleaved `v` lines count back from each face line (the OBJ spec), so the
    two triangles keep their own corners: hand-worked, z from 0 to 2, normalised by the extent 2."""
    (tmp_path / "rel.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
                                      "v 0 0 2\nv 1 0 2\nv 0 1 2\nf -3 -2 -1\n")
    scene = load_file_scene(tmp_path / "rel.obj", ground=False)
    triangles = np.concatenate([p.vertices[p.faces] for p in scene.parts])
    expected = (np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 2], [1, 0, 2], [0, 1, 2]]])
                - [0.5, 0.5, 0.0]) / 2.0
    got = sorted(map(tuple, triangles.reshape(-1, 3).round(9)))
    assert got == sorted(map(tuple, expected.reshape(-1, 3)))
    (tmp_path / "before.obj").write_text("v 0 0 0\nv 1 0 0\nf -3 -2 -1\nv 0 1 0\n")
    with pytest.raises(ValueError, match="before.obj: line 3: face index -3 reaches before the first v"):
        load_file_scene(tmp_path / "before.obj")


def _glb_with_png(tmp_path: Path, png: bytes) -> Path:
    box = trimesh.creation.box((2.0, 1.0, 3.0))
    image = Image.fromarray(np.full((8, 8, 3), 200, np.uint8))
    box.visual = trimesh.visual.TextureVisuals(uv=np.random.default_rng(1).random((len(box.vertices), 2)),
                                               image=image)
    glb = trimesh.exchange.gltf.export_glb(trimesh.Scene(box))
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    original = buffer.getvalue()
    assert glb.count(original) == 1 and len(png) == len(original)  # same length: offsets stay valid
    path = tmp_path / "tex.glb"
    path.write_bytes(glb.replace(original, png))
    return path


def _huge_png_header(length: int) -> bytes:
    """A PNG signature and an IHDR claiming 30000 x 30000 (CRC right), padded to `length`."""
    body = struct.pack(">IIBBBBB", 30000, 30000, 8, 2, 0, 0, 0)
    head = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + body + struct.pack(">I", zlib.crc32(
        b"IHDR" + body))
    return head + bytes(length - len(head))


@pytest.mark.parametrize("kind", ["huge_header", "random_bytes"])
def test_corrupt_embedded_texture_reported(tmp_path, fresh_cache, kind):
    buffer = io.BytesIO()
    Image.fromarray(np.full((8, 8, 3), 200, np.uint8)).save(buffer, format="PNG")
    length = len(buffer.getvalue())
    png = (_huge_png_header(length) if kind == "huge_header"
           else bytes(np.random.default_rng(2).integers(0, 256, length, dtype=np.uint8)))
    with pytest.raises(ValueError, match="tex.glb: a texture cannot be used"):
        load_file_scene(_glb_with_png(tmp_path, png))


def test_corrupt_texture_file_reported(tmp_path, fresh_cache):
    (tmp_path / "tex.jpg").write_bytes(b"\xff\xd8\xff" + bytes(np.random.default_rng(3).integers(
        0, 256, 500, dtype=np.uint8)))
    (tmp_path / "m.mtl").write_text("newmtl a\nmap_Kd tex.jpg\n")
    (tmp_path / "model.obj").write_text(f"mtllib m.mtl\nusemtl a\n{TRIANGLE_OBJ}")
    with pytest.raises(ValueError, match="model.obj: a texture cannot be used .failed to load image"):
        load_file_scene(tmp_path / "model.obj")


def test_mtl_options_before_map_kd_file_parsed(tmp_path, fresh_cache):
    image = np.zeros((8, 8, 3), np.uint8)
    image[:, :, 0] = 255
    Image.fromarray(image).save(tmp_path / "my tex.png")
    options = "-s 2 2 1 -o 0.5 0.5 0 -clamp off"
    (tmp_path / "m.mtl").write_text(f"newmtl a\nKd 1 1 1\nmap_Kd {options} my tex.png\n")
    (tmp_path / "model.obj").write_text(f"mtllib m.mtl\nusemtl a\n{TRIANGLE_OBJ}")
    (part,) = load_file_scene(tmp_path / "model.obj", ground=False).parts
    assert part.material.texture is not None and part.material.texture.parent.name == "mesh_textures"
    assert np.array_equal(np.asarray(Image.open(part.material.texture)), image)


def test_ply_declared_counts_exceed_body_refused(tmp_path):
    text = _box_ply().replace("element face 12", "element face 10000000")
    assert "element face 10000000" in text
    (tmp_path / "short.ply").write_text(text)
    with pytest.raises(ValueError, match="short.ply: its header declares 10000008 element lines .* its body "
                                         "holds 20"):
        load_file_scene(tmp_path / "short.ply")
