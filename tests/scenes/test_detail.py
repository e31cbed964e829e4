"""Unique surface detail (issue 29): no two faces of a building share a texture; `@tiled` is the old look."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from PIL import Image

from render.scan_cache import scene_digest
from scenes.buildings import build_building
from scenes.catalog import load_scene, split_look
from scenes.detail import detail_part
from scenes.model import Material
from scenes.presets import PRESETS
from scenes.surface import make_part, planar_uv
from scenes.textures import texture_path
from tests.scene_bytes import scene_bytes_digest

SMALL = replace(PRESETS["alpine_chalet"], width=8.0, depth=6.0, storeys=1, wall_roles=("stone_walls",),
                balcony_storeys=(), chimneys=0)
"""A one-storey chalet: every role of a preset, built in about a second."""
SMALL_TILED_DIGEST = "aab2d65b5231933d"
"""`scene_bytes_digest` (first 16 hex digits) of `build_building("small", SMALL)` at a127bd7, before
surface detail existed."""


def _box_walls() -> np.ndarray:
    """(8, 3, 3) corners of the four walls of a 6 x 6 x 3 m box, two triangles each."""
    walls = []
    for a, b in (((-3, -3), (3, -3)), ((3, -3), (3, 3)), ((3, 3), (-3, 3)), ((-3, 3), (-3, -3))):
        q = np.array([[*a, 0.0], [*b, 0.0], [*b, 3.0], [*a, 3.0]])
        walls += [q[[0, 1, 2]], q[[0, 2, 3]]]
    return np.array(walls)


def _crops(image: np.ndarray, part) -> list[np.ndarray]:
    """The texels under each wall (faces 2k, 2k + 1), by the wall's UV box."""
    uv = part.uv[part.faces] * np.array([image.shape[1], image.shape[0]])
    crops = []
    for k in range(0, len(uv), 2):
        lo, hi = np.ceil(uv[k:k + 2].reshape(-1, 2).min(0)).astype(int), uv[k:k + 2].reshape(-1, 2).max(0)
        crops.append(image[lo[1]:lo[1] + 40, lo[0]:lo[0] + 80].astype(float))
        assert np.all(hi - lo >= (80, 40))
    return crops


def test_opposite_walls_of_a_symmetric_box_get_different_textures():
    corners = _box_walls()
    tiled = make_part("walls", corners, planar_uv(corners, 1.6),
                      Material("walls", texture=texture_path("plaster_white", 0, size=64)))
    tile = np.asarray(Image.open(tiled.material.texture).convert("RGB"))
    tiled_uv = tiled.uv[tiled.faces]
    assert np.allclose(tiled_uv[0], tiled_uv[4])  # tiled: front and back walls sample the same texels
    detailed = detail_part(tiled, seed=1)
    atlas = np.asarray(Image.open(detailed.material.texture).convert("RGB"))
    assert detailed.material.texture != tiled.material.texture and atlas.shape[0] > tile.shape[0]
    uv = detailed.uv[detailed.faces]
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    front, right, back, left = _crops(atlas, detailed)
    for a, b in ((front, back), (right, left), (front, right)):
        assert np.abs(a - b).mean() > 8.0  # grey levels
    assert np.allclose(detailed.vertices[detailed.faces], tiled.vertices[tiled.faces])


def test_detail_is_seeded_and_its_name_does_not_depend_on_the_cache_folder(tmp_path, monkeypatch):
    corners = _box_walls()
    tiled = make_part("walls", corners, planar_uv(corners, 1.6),
                      Material("walls", texture=texture_path("plaster_white", 0, size=64)))
    first, again, other = detail_part(tiled, 1), detail_part(tiled, 1), detail_part(tiled, 2)
    assert first.material.texture == again.material.texture != other.material.texture
    assert first.material.texture.read_bytes() != other.material.texture.read_bytes()
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "elsewhere"))
    moved = make_part("walls", corners, planar_uv(corners, 1.6),
                      Material("walls", texture=texture_path("plaster_white", 0, size=64)))
    elsewhere = detail_part(moved, 1).material.texture
    assert elsewhere.name == first.material.texture.name and elsewhere.read_bytes() == \
        first.material.texture.read_bytes()


def test_tiled_flag_restores_the_old_textures_bit_exactly_and_keys_differ():
    tiled, detailed = build_building("small", SMALL, detail=False), build_building("small", SMALL)
    assert scene_bytes_digest(tiled)[:16] == SMALL_TILED_DIGEST
    assert [p.name for p in tiled.parts] == [p.name for p in detailed.parts]
    for a, b in zip(tiled.parts, detailed.parts):
        assert np.array_equal(np.unique(a.vertices, axis=0), np.unique(b.vertices, axis=0))
        assert a.material.texture.parent.name == "textures" and b.material.texture.parent.name == "atlases"
    walls = next(p for p in detailed.parts if p.name == "stone_walls")
    assert len({c.tobytes() for c in _wall_texels(walls)}) == 4  # each of the 4 walls its own texels
    assert scene_digest(tiled) != scene_digest(detailed)


def _wall_texels(part) -> list[np.ndarray]:
    """The atlas texels at the middle of each outward wall (normal along x or y, as long as the front)."""
    atlas = np.asarray(Image.open(part.material.texture).convert("RGB"))
    corners, uv = part.vertices[part.faces], part.uv[part.faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    out = []
    for axis, sign in ((0, 1), (0, -1), (1, 1), (1, -1)):
        face = np.argmax(sign * normal[:, axis] / (np.linalg.norm(normal, axis=1) + 1e-12)
                         + sign * corners[:, :, axis].mean(1) * 1e-3)
        x, y = (uv[face].mean(0) * np.array([atlas.shape[1], atlas.shape[0]])).astype(int)
        out.append(atlas[y - 2:y + 3, x - 2:x + 3])
    return out


@pytest.mark.parametrize("spec, expected", [("medieval_tavern", ("medieval_tavern", True)),
                                            ("random:3@tiled", ("random:3", False)),
                                            ("family:7@tiled", ("family:7", False))])
def test_tiled_suffix_names_the_old_look(spec, expected):
    assert split_look(spec) == expected


def test_tiled_suffix_on_another_scene_is_refused():
    with pytest.raises(ValueError, match="@tiled applies to a preset, random:SEED or family:SEED only"):
        load_scene("test_building@tiled")
