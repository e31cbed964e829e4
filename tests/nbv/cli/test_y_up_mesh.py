"""A user's Y-up textured OBJ through `nbv plan` and `nbv train`: read Y up, planned, trained on."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

import scenes.catalog
from nbv.cli import main
from nbv.rl.checkpoint import load_checkpoint
from render.dataset import read_dataset

SIZE_XYZ = (0.6, 1.0, 0.4)
"""The box in the file's axes: Y, its up axis, is the longest side, so it stands 1.0 tall once normalised
(0.4 if it were read Z up)."""
UPRIGHT_XYZ = (0.6, 0.4, 1.0)
"""Its normalised extents when read Y up: the file's Y becomes z, its Z becomes -y."""
TINY = ["--width", "64", "--height", "48", "--spp", "1"]


def write_y_up_obj(folder: Path) -> Path:
    """A textured box (OBJ + MTL + PNG) whose up axis is Y."""
    mesh = trimesh.creation.box(SIZE_XYZ)
    rng = np.random.default_rng(0)
    texture = Image.fromarray((rng.random((64, 64, 3)) * 255).astype(np.uint8)).resize((256, 256))
    mesh.visual = trimesh.visual.TextureVisuals(uv=rng.random((len(mesh.vertices), 2)), image=texture)
    path = folder / "house.obj"
    mesh.export(path)
    assert {p.suffix for p in folder.iterdir()} >= {".obj", ".mtl", ".png"}
    return path


def extents(mesh: trimesh.Trimesh) -> np.ndarray:
    return mesh.bounds[1] - mesh.bounds[0]


def test_plan_reads_a_y_up_obj_upright(tmp_path, capsys):
    obj = write_y_up_obj(tmp_path)
    reference = tmp_path / "reference.ply"
    scenes.catalog.load_scene(str(obj), "y").target_mesh().export(reference)  # skip the 288-view scan
    out = tmp_path / "plan"
    args = ["plan", str(obj), "--up-axis", "y", "--planner", "circle", "--views", "3", *TINY,
            "--reference", str(reference), "--metric-points", "2000", "--voxel-size-m", "0.01",
            "--out", str(out)]
    assert main(args) == 0
    assert extents(trimesh.load(out / "gt.ply")) == pytest.approx(UPRIGHT_XYZ, abs=1e-6)
    dataset = read_dataset(out / "views")
    assert len(dataset) == 3 and dataset.meta["up_axis"] == "y"
    plan = json.loads((out / "plan.json").read_text())
    assert plan["config"]["scene"] == {"up_axis": "y", "scene": str(obj)}
    assert 0.0 < plan["gt"]["coverage"] <= 1.0 and (out / "mesh.ply").is_file()
    assert '"planner": "circle"' in capsys.readouterr().out


def test_train_flies_around_a_y_up_obj(tmp_path, monkeypatch):
    obj = write_y_up_obj(tmp_path)
    loaded = []
    load_scene = scenes.catalog.load_scene

    def spy(spec: str, up_axis: str = "z"):
        scene = load_scene(spec, up_axis)
        lo, hi = scene.bounds()
        loaded.append((spec, up_axis, tuple(hi - lo)))
        return scene

    monkeypatch.setattr(scenes.catalog, "load_scene", spy)
    run = tmp_path / "run"
    args = ["train", "--scene", str(obj), "--up-axis", "y", *TINY, "--obs-size", "32", "--max-steps", "3",
            "--episode-views", "0", "--feature-backend", "opencv", "--frames", "2", "--frames-per-batch", "2",
            "--init-random-frames", "2", "--members", "1", "--validation-scenes", "--out", str(run),
            "--no-progress"]
    assert main(args) == 0
    assert load_checkpoint(run / "checkpoint.pt")["counters"]["frames"] == 2
    recorded = json.loads((run / "config.json").read_text())["env"]["scenes"]
    assert recorded == {"up_axis": "y", "scene": [str(obj)]}
    assert len(loaded) >= 2  # checked up front, then loaded by the env's renderer
    for spec, up_axis, size in loaded:
        assert (spec, up_axis) == (str(obj), "y") and size == pytest.approx(UPRIGHT_XYZ, abs=1e-6)
