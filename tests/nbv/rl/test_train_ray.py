"""`nbv train --collector ray`: two Ray collector actors on a local 2-CPU instance; resume; weight sync."""

from __future__ import annotations

import csv

import pytest
import ray
import torch

from nbv.bov.config import BoVConfig
from nbv.cli import main
from nbv.features.config import FeatureConfig
from nbv.rl.builders import make_ray_collector, make_sac_agent
from nbv.rl.checkpoint import load_checkpoint
from nbv.rl.config import CollectorConfig, EnvConfig, NetworkConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSet
from tests.nbv.rl.test_train import TINY_ENV


def test_a_ray_collected_run_checkpoints_and_resumes(tmp_path, monkeypatch):
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    run = tmp_path / "run"
    args = ["train", *TINY_ENV, "--collector", "ray", "--collectors", "2", "--frames-per-batch", "2",
            "--init-random-frames", "2", "--out", str(run), "--no-progress"]
    assert main([*args, "--frames", "4"]) == 0
    assert load_checkpoint(run / "checkpoint.pt")["counters"]["frames"] == 4
    assert not ray.is_initialized()  # the local instance it started is gone
    assert main([*args, "--frames", "8"]) == 0
    state = load_checkpoint(run / "checkpoint.pt")
    assert state["counters"] == {"frames": 8, "updates": 8} and "env" not in state
    with open(run / "metrics.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["frames"]) for r in rows] == [2, 4, 6, 8]
    assert main([*args, "--collectors", "1", "--frames", "10"]) == 2  # a different collection is refused


def test_the_ray_collectors_act_with_the_learners_weights(monkeypatch):
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32,
                    max_steps=3)
    actor, _ = make_sac_agent(env, NetworkConfig())
    config = CollectorConfig(frames=4, frames_per_batch=2, init_random_frames=0, collector="ray")
    collector = make_ray_collector(env, actor, config, seed=0)
    try:
        batches = iter(collector)
        assert next(batches).shape == (2, 1)  # one step from each collector
        with torch.no_grad():
            for param in actor.parameters():
                param.add_(1.0)  # what the optimiser does between batches: in place
        next(batches)
        mine = actor.state_dict()
        for remote in collector.remote_collectors:
            theirs = ray.get(remote.state_dict.remote())["policy_state_dict"]
            assert theirs.keys() == mine.keys()
            assert all(torch.equal(theirs[key], mine[key]) for key in mine)
    finally:
        collector.shutdown()


def test_ray_collection_settings_are_checked():
    with pytest.raises(ValueError, match="one env per collector"):
        CollectorConfig(collector="ray", envs=2)
    with pytest.raises(ValueError, match=r"frames_per_batch \(3\) must be a multiple of collectors \(2\)"):
        CollectorConfig(collector="ray", collectors=2, frames_per_batch=3)
