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


def test_a_process_builds_a_scene_once_and_nobody_can_change_it():
    first = load_scene("test_building")
    assert load_scene("test_building") is first
    with pytest.raises(ValueError, match="read-only"):
        first.parts[0].vertices[0, 0] = 1.0


def test_a_rewritten_mesh_file_or_another_up_axis_is_loaded_afresh(tmp_path):
    path = tmp_path / "tri.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    z_up = load_scene(str(path))
    assert load_scene(str(path)) is z_up
    y_up = load_scene(str(path), "y")
    assert y_up is not z_up and float(y_up.bounds()[1][2]) == pytest.approx(1.0)  # y turned to z
    path.write_text("v 0 0 0\nv 2 0 0\nv 0 0 1\nf 1 2 3\n")  # a new size: a new file state
    assert load_scene(str(path)) is not z_up
