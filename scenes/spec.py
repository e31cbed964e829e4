"""What names a target: a built-in scene or a mesh file, with the up axis of that file.

Light on purpose (no mesh or texture code), so the command line can build its
parser from these classes without loading anything. The `up_axis` knob is
declared once here and reaches every command that takes a scene.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

from tyro.conf import Positional, UseAppendAction, arg

from scenes.axes import UpAxis

if TYPE_CHECKING:
    from scenes.model import Scene


@dataclass(frozen=True, kw_only=True)
class MeshOrientation:
    """How to read a mesh file's axes (built-in scenes are z up and ignore it)."""

    up_axis: UpAxis = "z"
    """Up axis of a mesh file given as a scene (z or y)."""


@dataclass(frozen=True, kw_only=True)
class SceneSpec(MeshOrientation):
    """One target, given as the command's positional SCENE."""

    scene: Annotated[str, Positional, arg(metavar="SCENE")]
    """A built-in scene name (see `nbv scene list`), random:SEED, family:SEED, or a mesh / Mitsuba XML file
    path; a preset, random:SEED or family:SEED with @tiled (medieval_tavern@tiled) has the old tiled
    textures instead of unique surface detail."""

    def load(self) -> Scene:
        """The normalised scene."""
        from scenes.catalog import load_scene

        return load_scene(self.scene, self.up_axis)


@dataclass(frozen=True, kw_only=True)
class SceneSet(MeshOrientation):
    """One or more targets, each given with `--scene` (the up axis applies to every mesh file)."""

    scene: Annotated[tuple[str, ...], UseAppendAction]
    """A built-in scene name, random:SEED, family:SEED (each building with @tiled for the old tiled look), or
    a mesh file path; give --scene several times for several (`nbv train`: the scenes given replace the
    preset's, whatever tyro's "appends to" says)."""

    def __post_init__(self) -> None:
        if not self.scene:
            raise ValueError("need at least one scene")

    def specs(self) -> tuple[SceneSpec, ...]:
        """Each scene as its own spec."""
        return tuple(SceneSpec(scene=name, up_axis=self.up_axis) for name in self.scene)
