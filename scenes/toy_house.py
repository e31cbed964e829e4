"""`test_building`: a small textured house used by the foundation tests.

A 1.0 x 0.6 m box with a gable roof (apex at 0.8 m), brick walls, a tiled roof
and a grass ground, textured by `scenes.textures` at 512 px to stay quick.
Built already normalised: it stands on z = 0, is centred on the z axis, and
its largest side is 1 m.
"""

from __future__ import annotations

import numpy as np

from scenes.model import Lighting, Material, Part, Scene
from scenes.surface import make_part, planar_uv
from scenes.textures import texture_path

_SIZE_X, _SIZE_Y, _WALL_H, _APEX_H = 1.0, 0.6, 0.55, 0.8
_TEXTURE_PX = 512


def _fan(polygons: list[np.ndarray]) -> np.ndarray:
    """(F, 3, 3) triangle corners of convex planar polygons, fan-triangulated from their first vertex."""
    return np.array([[poly[0], poly[i], poly[i + 1]] for poly in polygons for i in range(1, len(poly) - 1)])


def _part(name: str, polygons: list[np.ndarray], texture: str, seed: int, tile_m: float,
          target: bool = True) -> Part:
    corners = _fan(polygons)
    material = Material(name, texture=texture_path(texture, seed, _TEXTURE_PX))
    return make_part(name, corners, planar_uv(corners, tile_m), material, target)


def build_test_building(seed: int = 0) -> Scene:
    """The test building scene (textures seeded by `seed`)."""
    x, y, h, a = _SIZE_X / 2, _SIZE_Y / 2, _WALL_H, _APEX_H
    c = np.array
    walls = [
        c([[-x, -y, 0], [x, -y, 0], [x, -y, h], [-x, -y, h]]),
        c([[x, y, 0], [-x, y, 0], [-x, y, h], [x, y, h]]),
        c([[x, -y, 0], [x, y, 0], [x, y, h], [x, 0, a], [x, -y, h]]),
        c([[-x, y, 0], [-x, -y, 0], [-x, -y, h], [-x, 0, a], [-x, y, h]]),
    ]
    roof = [
        c([[-x, -y, h], [x, -y, h], [x, 0, a], [-x, 0, a]]),
        c([[x, y, h], [-x, y, h], [-x, 0, a], [x, 0, a]]),
    ]
    g = 3.0
    ground = [c([[-g, -g, 0], [g, -g, 0], [g, g, 0], [-g, g, 0]])]
    return Scene(
        name="test_building",
        parts=(
            _part("walls", walls, "brick_red", seed, 0.25),
            _part("roof", roof, "roof_tiles_red", seed + 1, 0.4),
            _part("ground", ground, "grass", seed + 2, 0.5, target=False),
        ),
        lighting=Lighting(),
    )
