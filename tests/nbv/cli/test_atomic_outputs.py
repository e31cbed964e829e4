"""Every command's output is all or nothing: an interrupted run keeps the previous output, leaves no
partial new one, and the next run clears what a dead run left behind (issue 13)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
import trimesh
from synthetic import write_circle_dataset

from common.io import atomic_folder, replace_folder
from nbv.cli import main
from nbv.flight import flight_record
from render.camera import UAVCamera
from render.dataset import DatasetWriter
from render.raycast import DepthRaycaster
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene

FLIGHT = {"viewpoints": [[2.0, 1.0, 0.5]],
          **flight_record(Viewpoint(2.0, 0.0, 0.5), [Viewpoint(2.0, 1.0, 0.5)])}
"""A one-view flight record, as plan.json holds it (compare reads it)."""

CAMERA = UAVCamera(64, 48)


def hold_swap(monkeypatch: pytest.MonkeyPatch, out: Path) -> None:
    """Ctrl-C arrives as the finished temporary folder is renamed onto `out` (the old one moved aside:
    the two-rename swap of systems without an atomic exchange)."""
    monkeypatch.setattr("common.io._exchange", lambda a, b: False)
    rename = Path.rename

    def interrupted(self: Path, target):
        if self.name.startswith(f".{out.name}.tmp-") and Path(target) == out:
            raise KeyboardInterrupt
        return rename(self, target)

    monkeypatch.setattr(Path, "rename", interrupted)


def leftovers(out: Path) -> list[str]:
    """Hidden temporary or set-aside folders of `out` beside it."""
    return sorted(p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}."))


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under `folder` by relative path, with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def dead_pid() -> int:
    """The id of a process that has exited."""
    child = subprocess.Popen(["true"])
    child.wait()
    return child.pid


def test_atomic_folder_keeps_the_old_output_when_the_swap_is_interrupted(tmp_path, monkeypatch):
    out = tmp_path / "run"
    with atomic_folder(out) as folder:
        (folder / "a.txt").write_text("old")
    hold_swap(monkeypatch, out)
    with pytest.raises(KeyboardInterrupt), atomic_folder(out, overwrite=True) as folder:
        (folder / "a.txt").write_text("new")
    assert (out / "a.txt").read_text() == "old" and leftovers(out) == []


def test_atomic_folder_error_in_block_and_no_overwrite(tmp_path):
    out = tmp_path / "run"
    with pytest.raises(RuntimeError), atomic_folder(out) as folder:
        (folder / "a.txt").write_text("half")
        raise RuntimeError("boom")
    assert not out.exists() and leftovers(out) == []
    out.mkdir()
    (out / "keep.txt").write_text("x")
    with pytest.raises(FileExistsError, match="--overwrite"), atomic_folder(out):
        pass
    with atomic_folder(out, outputs=("a.txt",)) as folder:  # named outputs: other files carried over
        (folder / "a.txt").write_text("a")
    assert sorted(p.name for p in out.iterdir()) == ["a.txt", "keep.txt"]


def test_replace_folder_exchanges_in_one_step_where_the_os_can(tmp_path, monkeypatch):
    old, new = tmp_path / "out", tmp_path / ".out.tmp-1-x"
    old.mkdir(), new.mkdir()
    (new / "f").write_text("new")

    def no_rename(self: Path, target):
        raise AssertionError("renamed in two steps")

    monkeypatch.setattr(Path, "rename", no_rename)
    try:
        replace_folder(new, old)
    except AssertionError:
        pytest.skip("no RENAME_EXCHANGE on this file system")
    assert (old / "f").read_text() == "new" and leftovers(old) == []


def test_replace_folder_puts_the_old_one_back_when_the_second_rename_fails(tmp_path, monkeypatch):
    old, new = tmp_path / "out", tmp_path / ".out.tmp-1-x"
    old.mkdir(), new.mkdir()
    (old / "f").write_text("old")
    monkeypatch.setattr("common.io._exchange", lambda a, b: False)
    rename, calls = Path.rename, []

    def second_fails(self: Path, target):
        calls.append(self)
        if len(calls) == 2:
            raise OSError("disk gone")
        return rename(self, target)

    monkeypatch.setattr(Path, "rename", second_fails)
    with pytest.raises(OSError):
        replace_folder(new, old)
    assert (old / "f").read_text() == "old" and leftovers(old) == [new.name]


def test_stale_folders_of_a_dead_run_are_cleared_or_restored(tmp_path):
    out, pid = tmp_path / "run", dead_pid()
    (tmp_path / f".run.tmp-{pid}-abc").mkdir()
    (tmp_path / f".run.old-{pid}").mkdir()
    (tmp_path / f".run.old-{pid}" / "a.txt").write_text("previous")
    (tmp_path / f".run.tmp-{os.getpid()}-live").mkdir()  # a live run's folder is left alone
    with pytest.raises(FileExistsError):  # the set-aside output came back: it is not lost
        with atomic_folder(out):
            pass
    assert (out / "a.txt").read_text() == "previous"
    assert leftovers(out) == [f".run.tmp-{os.getpid()}-live"]


def test_scan_writer_interrupted_at_the_swap(tmp_path, monkeypatch):
    out = write_circle_dataset(tmp_path / "ds", [0, 1], size=(32, 24))
    before = snapshot(out)
    hold_swap(monkeypatch, out)
    with pytest.raises(KeyboardInterrupt):
        with DatasetWriter(out, UAVCamera(32, 24), {}, overwrite=True) as writer:
            writer.add(np.zeros((24, 32, 3), np.uint8), np.ones((24, 32)), np.eye(4))
    assert snapshot(out) == before and leftovers(out) == []


def test_refine_interrupted_keeps_the_previous_output(tmp_path, monkeypatch):
    source = write_circle_dataset(tmp_path / "ds", [0, 1, None, 2], size=(64, 48))
    out, common = tmp_path / "r", ["--max-features", "40", "--cache-dir", str(tmp_path / "cache")]
    assert main(["refine", str(source), "--out", str(out), "--ranges", "2", *common]) == 0
    before = snapshot(out)
    assert "refine.json" in before
    hold_swap(monkeypatch, out)
    with pytest.raises(KeyboardInterrupt):
        main(["refine", str(source), "--out", str(out), "--ranges", "4", "--overwrite", *common])
    assert snapshot(out) == before and leftovers(out) == []
    monkeypatch.undo()
    (tmp_path / f".r.tmp-{dead_pid()}-x").mkdir()  # what a killed run leaves
    assert main(["refine", str(source), "--out", str(out), "--ranges", "4", "--overwrite", *common]) == 0
    assert json.loads((out / "refine.json").read_text())["settings"]["ranges"] == 4 and leftovers(out) == []


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    """Eight ray-cast views of the test building (no renderer)."""
    scene = load_scene("test_building")
    caster = DepthRaycaster([trimesh.Trimesh(p.vertices, p.faces) for p in scene.parts],
                            CAMERA.K, CAMERA.width, CAMERA.height)
    out = tmp_path_factory.mktemp("atomic") / "scan"
    with DatasetWriter(out, CAMERA, {"scene": scene.name, "center": scene.center().tolist()}) as writer:
        for k in range(8):
            view = Viewpoint(2.0, 2 * np.pi * k / 8, 0.5)
            c2w = viewpoint_to_c2w(view, scene.center())
            writer.add(np.full((48, 64, 3), 150, np.uint8), caster.depth(c2w), c2w, view)
    return out


def test_reconstruct_interrupted_keeps_all_three_old_files(dataset, tmp_path, monkeypatch):
    out = tmp_path / "recon"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    fast = ["--voxel-size-m", "0.02", "--truncation-m", "0.08"]
    assert main(["reconstruct", str(dataset), "--out", str(out), *fast]) == 0
    before = snapshot(out)
    assert set(before) == {"mesh.ply", "points.ply", "reconstruction.json", "notes.txt"}
    hold_swap(monkeypatch, out)
    with pytest.raises(KeyboardInterrupt):
        main(["reconstruct", str(dataset), "--out", str(out), "--voxel-size-m", "0.03", "--truncation-m",
              "0.09", "--overwrite"])
    assert snapshot(out) == before and leftovers(out) == []


def test_evaluate_error_midway_leaves_no_partial_output(tmp_path, monkeypatch):
    mesh = tmp_path / "m.ply"
    load_scene("test_building").target_mesh().export(mesh)
    out = tmp_path / "ev"

    def args(folder: Path) -> list[str]:
        return ["evaluate", str(mesh), "--gt", str(mesh), "--out", str(folder), "--metric-points", "2000"]

    assert main(args(out)) == 0
    before = snapshot(out)
    assert {"metrics.json", "heatmap.png", "heatmap.ply"} <= set(before)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # after the heat map, before metrics.json

    monkeypatch.setattr("nbv.recon.evaluate.write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        main([*args(out), "--overwrite", "--seed", "3"])
    assert snapshot(out) == before and leftovers(out) == []
    with pytest.raises(KeyboardInterrupt):
        main(args(tmp_path / "fresh"))
    assert not (tmp_path / "fresh").exists() and leftovers(tmp_path / "fresh") == []


def test_plan_interrupted_keeps_the_previous_output(tmp_path, monkeypatch):
    reference = tmp_path / "reference.ply"
    load_scene("test_building").target_mesh().export(reference)
    out = tmp_path / "plan"
    out.mkdir()
    (out / "old.txt").write_text("previous plan")

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # the last step: views, meshes and metrics are written by now

    monkeypatch.setattr("nbv.planning.plan.plot_trajectory", interrupted)
    with pytest.raises(KeyboardInterrupt):
        main(["plan", "test_building", "--planner", "circle", "--views", "2", "--width", "32", "--height",
              "24", "--spp", "1", "--reference", str(reference), "--metric-points", "1000", "--voxel-size-m",
              "0.02", "--truncation-m", "0.08", "--out", str(out), "--overwrite"])
    assert snapshot(out) == {"old.txt": b"previous plan"} and leftovers(out) == []


def test_scene_export_interrupted_keeps_the_old_mesh(tmp_path, monkeypatch):
    out = tmp_path / "export"
    assert main(["scene", "export", "test_building", "--out", str(out)]) == 0
    (out / "readme.txt").write_text("kept")
    before, inode = snapshot(out), (out / "mesh.ply").stat().st_ino
    hold_swap(monkeypatch, out)
    with pytest.raises(KeyboardInterrupt):
        main(["scene", "export", "test_building", "--out", str(out), "--overwrite"])
    assert snapshot(out) == before and (out / "mesh.ply").stat().st_ino == inode and leftovers(out) == []


def test_refine_sweep_writes_its_three_files_together(tmp_path, monkeypatch):
    source = write_circle_dataset(tmp_path / "ds", [0, 1, 2], size=(64, 48))
    out = tmp_path / "s"
    args = ["refine-sweep", str(source), "--ranges", "1", "--words", "5", "--out", str(out), "--max-features",
            "40", "--cache-dir", str(tmp_path / "cache")]
    assert main(args) == 0
    before = snapshot(out)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # csv and md written, json not yet

    monkeypatch.setattr("nbv.bov.sweep.write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        main([*args[:-4], "--words", "7", *args[-4:]])
    assert snapshot(out) == before and leftovers(out) == []


def test_bench_interrupted_keeps_the_previous_figures(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from nbv.bench import BenchResult, suite

    class Area:
        value = 1.0

        def run(self, quick: bool) -> list[BenchResult]:
            return [BenchResult("fake", "figure", self.value, "s")]

    area = Area()
    monkeypatch.setattr(suite, "importlib", SimpleNamespace(import_module=lambda name: area))
    out = tmp_path / "bench"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    suite.run_bench(suite.BenchConfig(out=out, area=("cli",)))
    before = snapshot(out)
    assert set(before) == {"bench.json", "bench.md", "notes.txt"}
    area.value = 2.0

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # bench.md written, bench.json not yet

    monkeypatch.setattr(suite, "write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        suite.run_bench(suite.BenchConfig(out=out, area=("cli",)))
    assert snapshot(out) == before and leftovers(out) == []


def test_compare_interrupted_keeps_the_previous_comparison_and_the_runs(tmp_path, monkeypatch):
    from nbv.experiments.compare import CompareConfig, compare_planners
    from scenes.spec import SceneSpec

    metrics = {"coverage": 0.7, "chamfer_cm": 0.5, "hausdorff_cm": 8.0}
    out = tmp_path / "cmp"
    for seed in (0, 1):
        (out / f"random-seed{seed}").mkdir(parents=True)
        (out / f"random-seed{seed}" / "plan.json").write_text(
            json.dumps({"views": 13, "gt": metrics, "reference": metrics, "planning_s": 0.0,
                        "deciding_s": 0.0, **FLIGHT}))
    monkeypatch.setattr("nbv.experiments.compare.plot_planner_comparison",
                        lambda runs, paper, path, title: Path(path).write_bytes(b"png"))
    config = CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("random",), seeds=(0,), out=out)
    compare_planners(config)
    before = snapshot(out)
    assert {"comparison.json", "comparison.md", "comparison.png", "random-seed1/plan.json"} <= set(before)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # table and chart written, comparison.json not yet

    monkeypatch.setattr("nbv.experiments.compare.write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        compare_planners(CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("random",),
                                       seeds=(0, 1), out=out))
    assert snapshot(out) == before and leftovers(out) == []


def test_tables_interrupted_keeps_the_previous_tables_and_fig6(tmp_path, monkeypatch):
    from nbv.experiments.table2 import TablesConfig, run_tables

    grid = {"n": 5}

    def measure(name, config, progress=None, fig6=None):
        if fig6 is not None:  # the first seed's heat maps
            Path(fig6).mkdir(exist_ok=True)
            (Path(fig6) / f"fig6_{name}_N{grid['n']}.png").write_bytes(b"png")
        return [{"scene": name, "seed": config.seed, "ranges": grid["n"], "words": 10, "views": 3}]

    monkeypatch.setattr("nbv.experiments.table2.measure_scene", measure)
    monkeypatch.setattr("nbv.experiments.table2.plot_table2",
                        lambda rows, path: Path(path).write_bytes(b"png"))
    out = tmp_path / "paper_results"
    (out / "planners").mkdir(parents=True)
    (out / "planners" / "comparison.md").write_text("another command's result")
    run_tables(TablesConfig(out=out, scenes=("test_building",)))
    before = snapshot(out)
    assert {"table2.json", "table2.csv", "table2.md", "table2.png", "fig6/fig6_test_building_N5.png",
            "planners/comparison.md"} == set(before)
    grid["n"] = 7

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # fig6, csv, md and png in place, table2.json not yet

    monkeypatch.setattr("nbv.experiments.table2.write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_tables(TablesConfig(out=out, scenes=("test_building",)))
    assert snapshot(out) == before and leftovers(out) == []


def test_demo_interrupted_keeps_the_previous_results_and_the_cached_scan(tmp_path, monkeypatch):
    from nbv.experiments import demo
    from nbv.experiments.study import FullScanStudy

    out = tmp_path / "demo"

    def full_scan(self, scene, folder, fresh):
        if not folder.is_dir():
            folder.mkdir(parents=True)
            (folder / "transforms.json").write_text("{}")
        return folder

    def stages(config, scene, full, folder, clock, progress):
        (folder / "refined").mkdir()
        (folder / "refined" / "refine.json").write_text(json.dumps(config.seed))
        return {"seed": config.seed}, f"seed {config.seed}\n"

    monkeypatch.setattr(FullScanStudy, "load", lambda self, name: name)
    monkeypatch.setattr(FullScanStudy, "full_scan", full_scan)
    monkeypatch.setattr(demo, "demo_stages", stages)
    demo.run_demo(demo.DemoConfig(out=out, seed=1))
    before = snapshot(out)
    assert set(before) == {"full_scan/transforms.json", "refined/refine.json", "results.json", "results.md"}

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # every stage done, results.json not yet

    monkeypatch.setattr(demo, "write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        demo.run_demo(demo.DemoConfig(out=out, seed=2))
    assert snapshot(out) == before and leftovers(out) == []


def test_unwritable_out_is_one_line_naming_it(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    blocker.chmod(0o755)  # root may write anything; a file is still no folder
    out = blocker / "sub" / "export"
    assert main(["scene", "export", "test_building", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(out) in err and "not a folder" in err, err
    assert ".tmp-" not in err
    if Path("/proc/self").is_dir():  # /proc passes the up-front checks; mkdtemp's own error is named too
        assert main(["scene", "export", "test_building", "--out", "/proc/nbv-x"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "output folder /proc/nbv-x " in err and ".tmp-" not in err, err
