"""Scenes by name: presets, the `random:SEED` family, the test building, mesh and XML files."""

from __future__ import annotations

from collections.abc import Callable

from scenes.loader import is_scene_file, load_file_scene
from scenes.model import Scene
from scenes.presets import PRESETS, build_preset, build_random
from scenes.test_building import build_test_building

BUILTIN: dict[str, Callable[[], Scene]] = {
    **{name: (lambda name=name: build_preset(name)) for name in PRESETS},
    "test_building": build_test_building,
}
"""Built-in scene names and their builders."""

DEFAULT_SCENE = "medieval_tavern"
"""The scene `make demo` uses."""

RANDOM_PREFIX = "random:"
"""`random:SEED` names a building drawn from the grammar (see `scenes.presets`)."""


def list_scenes() -> list[str]:
    """Names of the built-in scenes (presets first, then the test building)."""
    return list(BUILTIN)


def load_scene(spec: str, up_axis: str = "z") -> Scene:
    """A scene by built-in name, `random:SEED`, or mesh / Mitsuba XML file path.

    Args:
        spec: what to load.
        up_axis: 'z' or 'y', the up axis of a mesh file (built-in scenes are z up).

    Raises:
        ValueError: unknown name, bad seed, unreadable or invalid mesh.
        FileNotFoundError: a mesh or XML path that does not exist.
    """
    if spec in BUILTIN:
        return BUILTIN[spec]()
    if spec.startswith(RANDOM_PREFIX):
        seed = spec[len(RANDOM_PREFIX) :]
        if not seed.isdigit():
            raise ValueError(f"bad scene {spec!r}: expected random:SEED with SEED a non-negative integer")
        return build_random(int(seed))
    if is_scene_file(spec):
        return load_file_scene(spec, up_axis)
    raise ValueError(
        f"unknown scene {spec!r}; built-in scenes: {', '.join(list_scenes())}; "
        f"or random:SEED, or a mesh / Mitsuba XML file path"
    )
