"""`nbv plan` end to end, tiny: views dataset, reconstruction, metrics.json, trajectory.png."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from nbv.bov.config import BoVConfig
from nbv.cli import main
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.plan import planning_env_config, reference_mesh
from nbv.planning.registry import make_planner
from nbv.recon.config import ReconstructionConfig
from nbv.rl.env import NBVEnv
from render.camera import UAVCamera
from render.dataset import read_dataset
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.spec import SceneSet, SceneSpec


def test_nbv_plan_end_to_end(tmp_path, capsys):
    reference = tmp_path / "reference.ply"
    load_scene("test_building").target_mesh().export(reference)
    out = tmp_path / "plan"
    args = ["plan", "test_building", "--planner", "circle", "--views", "6", "--width", "64", "--height", "48",
            "--spp", "1", "--reference", str(reference), "--metric-points", "3000", "--voxel-size-m", "0.01",
            "--out", str(out)]
    assert main(args) == 0
    dataset = read_dataset(out / "views")
    assert len(dataset) == 6 and dataset.meta["planner"] == "circle"
    metrics = json.loads((out / "metrics.json").read_text())
    for name in ("gt", "reference"):
        assert 0.0 < metrics[name]["coverage"] <= 1.0
        m = metrics[name]
        assert 0 < m["chamfer_cm"] <= m["hausdorff_cm"]
    plan = json.loads((out / "plan.json").read_text())
    assert plan["views"] == 6 and len(plan["viewpoints"]) == 6 and plan["gt"] == metrics["gt"]
    assert (out / "trajectory.png").stat().st_size > 10_000 and (out / "mesh.ply").is_file()
    assert '"planner": "circle"' in capsys.readouterr().out
    check_flight(plan)
    assert main(args) == 2  # refuses to overwrite without --overwrite


def check_flight(plan: dict) -> None:
    """plan.json's flight: from the seed's start view (default ranges) along the 6-view ring, no shorter
    than the straight lines, the ring's legs its arcs."""
    spans = np.array([1.0, 2 * math.pi, math.radians(75)])  # R 1.5-2.5 m, all azimuths, 5-80 degrees
    start = Viewpoint(*(np.array([1.5, 0.0, math.radians(5)]) + np.random.default_rng(0).random(3) * spans))
    assert plan["start_viewpoint"] == pytest.approx(start.as_array().tolist())
    centre = np.zeros(3)
    stops = np.stack([viewpoint_to_c2w(Viewpoint(*v), centre)[:3, 3]
                      for v in [plan["start_viewpoint"], *plan["viewpoints"]]])
    straight = np.linalg.norm(np.diff(stops, axis=0), axis=1)
    assert plan["flight_m"] >= straight.sum() and np.all(np.array(plan["legs_m"]) >= straight)
    assert plan["flight_m"] == pytest.approx(sum(plan["legs_m"])) and len(plan["legs_m"]) == 6
    ring_arc = 2.0 * math.cos(math.radians(42.5)) * math.pi / 3  # R cos(elevation) * 60 degrees
    assert plan["legs_m"][1:] == pytest.approx([ring_arc] * 5, rel=1e-4)
    assert plan["azimuth_reversals"] == 1  # the start (97 degrees) lies counter-clockwise of view 0


@pytest.mark.parametrize("planner", ["random", "infogain"])
def test_nbv_plan_with_a_reference_and_information_gain(planner, tmp_path, capsys):
    reference = tmp_path / "reference.ply"
    load_scene("test_building").target_mesh().export(reference)
    out = tmp_path / planner
    scoring = ["--reference", str(reference)] if planner == "random" else ["--no-full-scan"]  # gt only
    args = ["plan", "test_building", "--planner", planner, "--views", "3", "--candidates", "2",
            "--width", "64", "--height", "48", "--spp", "1", *scoring, "--metric-points", "3000",
            "--voxel-size-m", "0.01", "--grid-resolution", "16", "--out", str(out)]
    assert main(args) == 0
    plan = json.loads((out / "plan.json").read_text())
    assert ("reference" in plan) == (planner == "random")
    assert plan["planner"] == planner and plan["views"] == 3 and len(read_dataset(out / "views")) == 3
    assert 0.0 < plan["gt"]["coverage"] <= 1.0 and 0.0 <= plan["deciding_s"] <= plan["planning_s"]
    if planner == "infogain":  # its first view is the start view: the recorded start is the planner's
        assert plan["viewpoints"][0] == plan["start_viewpoint"] and plan["legs_m"][0] == 0.0
    settings = plan["config"]["settings"]
    assert settings["candidates"] == 2 and settings["occupancy"]["grid_resolution"] == 16
    assert f'"planner": "{planner}"' in capsys.readouterr().out


def test_nbv_plan_unknown_planner_is_a_clear_error(tmp_path, capsys):
    assert main(["plan", "test_building", "--planner", "best", "--out", str(tmp_path / "p")]) == 2
    assert "unknown planner" in capsys.readouterr().err


def test_reference_is_the_cached_full_scan_reconstruction(tmp_path):
    recon = ReconstructionConfig(voxel_size_m=0.02, truncation_m=0.08)  # 4 voxels, as before
    scene = SceneSpec(scene="test_building")  # no seed among the arguments: one reference for all
    settings = PlanSettings(camera=UAVCamera(48, 36), render=RenderSettings(spp=1), recon=recon)
    path = reference_mesh(scene, settings)
    assert path.name == "mesh.ply" and path.parent.name == "reconstruction_20mm"
    assert len(read_dataset(path.parent.parent)) == 288  # the paper's full hemisphere scan
    stamp = path.stat().st_mtime_ns
    assert reference_mesh(scene, settings) == path and path.stat().st_mtime_ns == stamp  # reused, not rebuilt
    other = replace(settings, recon=replace(settings.recon, truncation_m=0.06))
    assert reference_mesh(scene, other) == path and path.stat().st_mtime_ns != stamp  # other fusion: redone


def test_the_plans_bov_and_camera_reach_the_greedy_planners_env(tmp_path):
    settings = PlanSettings(camera=UAVCamera(64, 48, focal_mm=20.0),
                            bov=BoVConfig(ranges=4, match_cosine=0.6))
    config = PlanConfig(scene=SceneSpec(scene="house.obj", up_axis="y"), planner="greedy", out=tmp_path,
                        settings=settings)
    env = NBVEnv(planning_env_config(config, make_planner("greedy", settings)))
    assert env.bov.match_cosine == 0.6 and env.bov.ranges == 4
    assert env.config.camera.focal_mm == 20.0
    assert env.config.scenes == SceneSet(scene=("house.obj",), up_axis="y")


def test_choose_views_plans_on_the_thread_policy_and_restores_torch(tmp_path, monkeypatch):
    import torch

    from common import threads
    from nbv.planning.plan import choose_views, scan_env_config

    class Recorder:
        def plan(self, world, views):
            seen.append(torch.get_num_threads())
            return []

    config = PlanConfig(scene=SceneSpec(scene="house.obj", up_axis="y"), out=tmp_path)
    before, seen = torch.get_num_threads(), []
    monkeypatch.setattr(threads, "_chosen", None)
    try:
        torch.set_num_threads(2)
        choose_views(config, Recorder(), scan_env_config(config.scene, config.settings))
        threads.set_torch_threads(2)  # a process that chose keeps its choice
        choose_views(config, Recorder(), scan_env_config(config.scene, config.settings))
        assert seen == [threads.worker_threads(), 2] and torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)


def test_the_camera_time_of_the_views_flown_to():
    from nbv.planning.plan import flown_seconds

    assert flown_seconds(10.0, 5, 2) == pytest.approx(4.0)  # greedy: 2 of 5 renders were flown to
    assert flown_seconds(3.0, 1, 13) == pytest.approx(3.0)  # infogain: one RGB render for 13 views
    assert flown_seconds(0.0, 0, 13) == 0.0  # random: nothing rendered


def test_choose_views_counts_the_simulated_camera_apart_from_deciding(tmp_path):
    from nbv.planning.plan import choose_views, scan_env_config

    class Looker:  # renders 3 candidates beside its start view, flies to one view
        def plan(self, world, views):
            self.world = world
            start = world.start
            for azimuth in (start.azimuth, 0.5, 1.5, 2.5):
                world.source.render_rgb(Viewpoint(start.radius, azimuth, start.elevation))
            return [start]

    config = PlanConfig(scene=SceneSpec(scene="test_building"), out=tmp_path,
                        settings=PlanSettings(camera=UAVCamera(48, 36), render=RenderSettings(spp=1)))
    looker = Looker()
    views, seconds, camera = choose_views(config, looker, scan_env_config(config.scene, config.settings))
    clock = looker.world.source
    assert len(views) == 1 and clock.views_rendered == 4 and clock.setup_seconds > 0
    assert camera == pytest.approx(clock.setup_seconds + clock.render_seconds / 4) and camera < seconds
