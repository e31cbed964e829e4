"""Scenes by name: presets, the `random:SEED` and `family:SEED` families, the test building, mesh and XML
files.

Light to import: the names are listed here and each builder or loader is
imported when a scene is loaded, so `nbv scene list` starts at once.
"""

from __future__ import annotations

import os
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from common.io import cache_dir
from scenes.family_splits import FAMILY_PREFIX, parse_family

if TYPE_CHECKING:
    from scenes.model import Scene

PRESET_NAMES = ("medieval_tavern", "forest_ruin_house", "alpine_chalet", "imperial_temple")
"""The keys of `scenes.presets.PRESETS`, in order (kept here so listing them loads no mesh code)."""
TEST_BUILDING = "test_building"
"""The small test building (`scenes.toy_house`)."""
BUILTIN_NAMES = (*PRESET_NAMES, TEST_BUILDING)
"""Built-in scene names: presets first, then the test building."""
DEFAULT_SCENE = "medieval_tavern"
"""The scene `make demo` uses."""
RANDOM_PREFIX = "random:"
"""`random:SEED` names a building drawn from the grammar (see `scenes.presets`)."""
TILED_SUFFIX = "@tiled"
"""A procedural building's name ending in `@tiled` (`medieval_tavern@tiled`, `random:3@tiled`,
`family:7@tiled`) loads it with the old look: its tileable textures repeated over every face, without the
unique surface detail (weathering, stains, posters, growth at the base: `scenes.detail`) that the plain name
bakes by default."""
MEMO_SIZE = 8
"""Scenes a process keeps loaded (`load_scene`), the least recently used dropped first."""
_MEMO: OrderedDict[tuple, Scene] = OrderedDict()


def list_scenes() -> list[str]:
    """Names of the built-in scenes (presets first, then the test building)."""
    return list(BUILTIN_NAMES)


def load_scene(spec: str, up_axis: str = "z") -> Scene:
    """A scene by built-in name, `random:SEED`, `family:SEED`, or mesh / Mitsuba XML file path.

    A process builds each scene once (a procedural building takes seconds): the scene is kept, its
    arrays made read-only, and given again while its texture files and its mesh file are unchanged.

    Args:
        spec: what to load.
        up_axis: 'z' or 'y', the up axis of a mesh file (built-in scenes are z up).

    Raises:
        ValueError: unknown name, bad seed, unreadable or invalid mesh.
        FileNotFoundError: a mesh or XML path that does not exist.
    """
    key = _memo_key(spec, up_axis)
    scene = _MEMO.get(key)
    if scene is None or not all(part.material.texture is None or part.material.texture.exists()
                                for part in scene.parts):
        scene = _frozen(_build(spec, up_axis))
    _MEMO[key] = scene
    _MEMO.move_to_end(key)
    while len(_MEMO) > MEMO_SIZE:
        _MEMO.popitem(last=False)
    return scene


def _memo_key(spec: str, up_axis: str) -> tuple:
    """What a loaded scene depends on: the textures' cache folder, and a mesh file's state and up axis."""
    if spec in BUILTIN_NAMES or spec.startswith((RANDOM_PREFIX, FAMILY_PREFIX)) or not os.path.exists(spec):
        return spec, str(cache_dir())
    state = os.stat(spec)
    return str(Path(spec).resolve()), up_axis, state.st_mtime_ns, state.st_size, str(cache_dir())


def _frozen(scene: Scene) -> Scene:
    """`scene` with its arrays read-only, so no user of a shared scene can change it for the next."""
    for part in scene.parts:
        for array in (part.vertices, part.faces, part.uv):
            if array is not None:
                array.flags.writeable = False
    return scene


def split_look(spec: str) -> tuple[str, bool]:
    """A scene name without `TILED_SUFFIX`, and whether its surfaces get the unique detail (no suffix)."""
    base = spec.removesuffix(TILED_SUFFIX)
    if base != spec and not (base in PRESET_NAMES or base.startswith((RANDOM_PREFIX, FAMILY_PREFIX))):
        raise ValueError(f"bad scene {spec!r}: {TILED_SUFFIX} applies to a preset, random:SEED or "
                         f"family:SEED only, e.g. medieval_tavern{TILED_SUFFIX}")
    return base, base == spec


def _build(spec: str, up_axis: str) -> Scene:
    base, detail = split_look(spec)
    if base != spec:
        return replace(_build_building(base, detail), name=spec)
    return _build_building(spec, detail) or _build_other(spec, up_axis)


def _build_building(spec: str, detail: bool) -> Scene | None:
    """A preset, random:SEED or family:SEED building, None for any other name."""
    if spec in PRESET_NAMES:
        from scenes.presets import build_preset

        return build_preset(spec, detail=detail)
    if spec.startswith(RANDOM_PREFIX):
        seed = spec[len(RANDOM_PREFIX) :]
        if not seed.isdigit():
            raise ValueError(f"bad scene {spec!r}: expected random:SEED with SEED a non-negative integer")
        from scenes.presets import build_random

        return build_random(int(seed), detail)
    if spec.startswith(FAMILY_PREFIX):
        from scenes.family import build_family

        return build_family(parse_family(spec), detail)
    return None


def _build_other(spec: str, up_axis: str) -> Scene:
    """The test building or a mesh / Mitsuba XML file."""
    if spec == TEST_BUILDING:
        from scenes.toy_house import build_test_building

        return build_test_building()
    from scenes.loader import is_scene_file, load_file_scene

    if is_scene_file(spec):
        return load_file_scene(spec, up_axis)
    raise ValueError(
        f"unknown scene {spec!r}; built-in scenes: {', '.join(list_scenes())}; "
        f"or random:SEED, family:SEED (each with {TILED_SUFFIX} for the tiled look), or a mesh / Mitsuba XML "
        f"file path"
    )
