"""Scenes by name: presets, the `random:SEED` family, the test building, mesh and XML files.

Light to import: the names are listed here and each builder or loader is
imported when a scene is loaded, so `nbv scene list` starts at once.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from common.io import atomic_folder, check_output_folder
from scenes.spec import SceneSpec

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


def list_scenes() -> list[str]:
    """Names of the built-in scenes (presets first, then the test building)."""
    return list(BUILTIN_NAMES)


def load_scene(spec: str, up_axis: str = "z") -> Scene:
    """A scene by built-in name, `random:SEED`, or mesh / Mitsuba XML file path.

    Args:
        spec: what to load.
        up_axis: 'z' or 'y', the up axis of a mesh file (built-in scenes are z up).

    Raises:
        ValueError: unknown name, bad seed, unreadable or invalid mesh.
        FileNotFoundError: a mesh or XML path that does not exist.
    """
    if spec in PRESET_NAMES:
        from scenes.presets import build_preset

        return build_preset(spec)
    if spec == TEST_BUILDING:
        from scenes.toy_house import build_test_building

        return build_test_building()
    if spec.startswith(RANDOM_PREFIX):
        seed = spec[len(RANDOM_PREFIX) :]
        if not seed.isdigit():
            raise ValueError(f"bad scene {spec!r}: expected random:SEED with SEED a non-negative integer")
        from scenes.presets import build_random

        return build_random(int(seed))
    from scenes.loader import is_scene_file, load_file_scene

    if is_scene_file(spec):
        return load_file_scene(spec, up_axis)
    raise ValueError(
        f"unknown scene {spec!r}; built-in scenes: {', '.join(list_scenes())}; "
        f"or random:SEED, or a mesh / Mitsuba XML file path"
    )


@dataclass(frozen=True, kw_only=True)
class ExportConfig(SceneSpec):
    """Settings of `nbv scene export`: a target and the folder for its mesh."""

    out: Path
    """Output folder for mesh.ply."""
    overwrite: bool = False
    """Replace an existing OUT/mesh.ply."""


def export_scene(config: ExportConfig) -> Path:
    """Write the normalised target mesh (exactly as rendered, no ground) to `out/mesh.ply`, atomically
    (other files in `out` are kept)."""
    out = Path(config.out)
    check_output_folder(out, config.overwrite, ("mesh.ply",))
    mesh = config.load().target_mesh()
    with atomic_folder(out, config.overwrite, ("mesh.ply",)) as folder:
        mesh.export(folder / "mesh.ply", file_type="ply")
    return out / "mesh.ply"
