"""Scenes by name: built-in scenes and mesh file paths."""

from __future__ import annotations

from collections.abc import Callable

from scenes.model import Scene
from scenes.test_building import build_test_building

BUILTIN: dict[str, Callable[[], Scene]] = {
    "test_building": build_test_building,
}
"""Built-in scene names and their builders."""

DEFAULT_SCENE = "test_building"
"""The scene `make demo` uses."""


def list_scenes() -> list[str]:
    """Names of the built-in scenes."""
    return sorted(BUILTIN)


def load_scene(name: str) -> Scene:
    """A built-in scene by name; unknown names raise a ValueError listing the known ones."""
    if name not in BUILTIN:
        raise ValueError(f"unknown scene {name!r}; built-in scenes: {', '.join(list_scenes())}")
    return BUILTIN[name]()
