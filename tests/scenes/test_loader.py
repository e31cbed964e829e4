"""User meshes: round trips through OBJ+MTL+PNG and GLB, normalisation, up axis, bad input, big meshes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene


def _textured_box(size=(2.0, 1.0, 3.0)) -> tuple[trimesh.Trimesh, np.ndarray]:
    mesh = trimesh.creation.box(size)
    image = (np.random.default_rng(0).random((32, 32, 3)) * 255).astype(np.uint8)
    uv = np.random.default_rng(1).random((len(mesh.vertices), 2))
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, image=Image.fromarray(image))
    return mesh, image


@pytest.mark.parametrize("suffix", [".obj", ".glb"])
def test_textured_mesh_round_trips(tmp_path, suffix):
    mesh, image = _textured_box()
    path = tmp_path / f"box{suffix}"
    mesh.export(path)
    if suffix == ".obj":
        assert {p.suffix for p in tmp_path.iterdir()} >= {".obj", ".mtl", ".png"}
    scene = load_scene(str(path))
    (part,) = [p for p in scene.parts if p.target]
    assert len(part.faces) == len(mesh.faces)
    assert np.array_equal(np.asarray(Image.open(part.material.texture).convert("RGB")), image)
    # UVs come back per vertex, flipped to Mitsuba's convention (v down the image).
    source = {tuple(np.round(v / 3.0 + [0, 0, 0.5], 6)): uv for v, uv in zip(mesh.vertices, mesh.visual.uv)}
    for v, uv in zip(part.vertices, part.uv):
        expected = source[tuple(np.round(v, 6))]
        assert uv == pytest.approx([expected[0], 1.0 - expected[1]], abs=1e-6)


def test_mesh_is_normalised_and_y_up_is_turned_to_z(tmp_path):
    mesh = trimesh.creation.box((2.0, 4.0, 1.0))
    mesh.apply_translation([10.0, 5.0, -3.0])
    path = tmp_path / "box.ply"
    mesh.export(path)
    lo, hi = load_scene(str(path)).bounds()
    assert lo == pytest.approx([-0.25, -0.5, 0.0]) and hi == pytest.approx([0.25, 0.5, 0.25])
    lo, hi = load_scene(str(path), up_axis="y").bounds()  # the 4 m side (y) now stands upright
    assert hi - lo == pytest.approx([0.5, 0.25, 1.0])
    scene = load_scene(str(path))
    target = [p for p in scene.parts if p.target][0]
    assert target.uv is not None and target.material.texture is not None  # procedural texture


def test_texture_appears_upright_in_a_render(tmp_path):
    quad = trimesh.Trimesh(
        [[-1, 0, 0], [1, 0, 0], [1, 0, 2], [-1, 0, 2]], [[0, 1, 2], [0, 2, 3]], process=False
    )
    image = np.zeros((16, 16, 3), np.uint8)
    image[:8] = (255, 0, 0)  # top half red
    image[8:] = (0, 0, 255)
    quad.visual = trimesh.visual.TextureVisuals(
        uv=[[0, 0], [1, 0], [1, 1], [0, 1]], image=Image.fromarray(image)
    )
    quad.export(tmp_path / "quad.obj")
    scene = load_scene(str(tmp_path / "quad.obj"))
    renderer = MitsubaRenderer(scene, UAVCamera(64, 48), RenderSettings(spp=4, integrator="direct"))
    rgb = renderer.render_rgb(viewpoint_to_c2w(Viewpoint(2.2, -np.pi / 2, 0.0), scene.center()))
    top, bottom = rgb[14, 32].astype(int), rgb[34, 32].astype(int)
    assert top[0] > top[2] and bottom[2] > bottom[0]


def _write(path: Path, text: str) -> str:
    path.write_text(text)
    return str(path)


def test_bad_meshes_get_clear_errors(tmp_path):
    nan = _write(tmp_path / "nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match="nan.obj.*NaN"):
        load_scene(nan)
    index = _write(
        tmp_path / "index.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
    )
    with pytest.raises(ValueError, match="index.ply.*out of range"):
        load_scene(index)
    points = _write(
        tmp_path / "points.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
    )
    with pytest.raises(ValueError, match="points.ply.*no triangle mesh with faces"):
        load_scene(points)
    with pytest.raises(FileNotFoundError, match="missing.obj"):
        load_scene(str(tmp_path / "missing.obj"))
    with pytest.raises(ValueError, match="unknown scene 'castle'.*medieval_tavern"):
        load_scene("castle")
    with pytest.raises(ValueError, match="random:SEED"):
        load_scene("random:x")


def test_mitsuba_xml_is_accepted_as_is(tmp_path):
    xml = _write(tmp_path / "scene.xml", '<scene version="3.0.0"><shape type="sphere"/></scene>')
    scene = load_scene(xml)
    assert scene.mitsuba_xml == Path(xml).resolve() and scene.parts == ()


@pytest.mark.slow
def test_a_million_triangle_mesh_loads_normalises_and_renders(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=8, radius=3.0)  # 1.3 M triangles
    assert len(sphere.faces) >= 1_000_000
    sphere.export(tmp_path / "big.ply")
    scene = load_scene(str(tmp_path / "big.ply"))
    lo, hi = scene.bounds()
    assert lo[2] == pytest.approx(0.0) and np.max(hi - lo) == pytest.approx(1.0)
    renderer = MitsubaRenderer(scene, UAVCamera(64, 48), RenderSettings(spp=1))
    rgb, depth = renderer.render(viewpoint_to_c2w(Viewpoint(2.0, 0.5, 0.4), scene.center()))
    assert (depth > 0).mean() > 0.1 and rgb.std() > 0
