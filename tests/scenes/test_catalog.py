"""The scene catalog: its light name list matches the builders, and names resolve to scenes."""

from __future__ import annotations

import subprocess
import sys

import pytest

from scenes.catalog import BUILTIN_NAMES, PRESET_NAMES, list_scenes, load_scene


def test_the_light_name_list_matches_the_presets():
    from scenes.presets import PRESETS

    assert PRESET_NAMES == tuple(PRESETS)
    assert list_scenes() == [*PRESETS, "test_building"] == list(BUILTIN_NAMES)


def test_importing_the_catalog_loads_no_mesh_code():
    heavy = ("trimesh", "manifold3d", "PIL")
    code = f"import sys, scenes.catalog; print([m for m in {heavy!r} if m in sys.modules])"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize("spec, message", [("castle", "unknown scene 'castle'"), ("random:x", "random:SEED")])
def test_bad_names_are_named(spec, message):
    with pytest.raises(ValueError, match=message):
        load_scene(spec)
