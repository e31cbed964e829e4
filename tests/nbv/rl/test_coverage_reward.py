"""The coverage reward term: W x the share of the true surface a view is the episode's first to see,
checked against an independent visibility count; off in validation and planning (across a restore:
test_env's snapshot test)."""

from __future__ import annotations

import math

import pytest
import torch
from tensordict import TensorDict

from nbv.bov.config import BoVConfig
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import EnvConfig, LatticeConfig, ValidationConfig
from nbv.rl.env import NBVEnv
from nbv.rl.validate import validation_env_config
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import viewpoint_to_c2w
from scenes import load_scene
from scenes.spec import SceneSet

ACTIONS = ([0.0, 0.5, 0.3], [0.0, 0.0, 0.0], [0.4, -0.7, -0.2])
"""Relative steps: the second one stays put, so it can see nothing new."""


def config(**kwargs) -> EnvConfig:
    settings = dict(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1), bov=BoVConfig(ranges=4, words=5, features="opencv"),
                    obs_size=16, max_steps=5, action_mode="relative")
    return EnvConfig(**{**settings, **kwargs})


def fly(env: NBVEnv) -> tuple[list[float], list]:
    """Rewards of `ACTIONS` from the env's seeded start, and every viewpoint flown (start first)."""
    env.reset()
    views, rewards = [env.viewpoint], []
    for action in ACTIONS:
        out = env.step(TensorDict({"action": torch.tensor(action)}, []))
        views.append(env.viewpoint)
        rewards.append(float(out["next", "reward"]))
    return rewards, views


def new_shares(views: list) -> list[float]:
    """Share of the target's surface samples each view after the first sees first (an independent count)."""
    scene = load_scene("test_building")
    visibility = scene_visibility(scene, UAVCamera(64, 48))
    seen = visibility.seen(viewpoint_to_c2w(views[0], scene.center()))
    shares = []
    for view in views[1:]:
        now = visibility.seen(viewpoint_to_c2w(view, scene.center()))
        shares.append(float((now & ~seen).mean()))
        seen |= now
    return shares


def test_the_term_adds_w_times_the_newly_seen_share_to_the_bag_of_views_reward():
    bov_only, views = fly(NBVEnv(config(), seed=4))
    weighted, same_views = fly(NBVEnv(config(coverage_reward=50.0), seed=4))
    assert [v.as_array().tolist() for v in same_views] == [v.as_array().tolist() for v in views]
    shares = new_shares(views)
    assert shares[0] > 0.01 and shares[1] == 0.0  # a first move sees new surface; staying put does not
    expected = [r + 50.0 * s for r, s in zip(bov_only, shares)]
    assert weighted == pytest.approx(expected, abs=1e-4)


def test_on_a_lattice_the_term_counts_what_the_nodes_see(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(enabled=True, lattice_radii=2, lattice_azimuths=8, lattice_elevations=2)
    bov_only, views = fly(NBVEnv(config(lattice=grid), seed=2))
    env = NBVEnv(config(lattice=grid, coverage_reward=20.0), seed=2)
    weighted, _ = fly(env)
    lattice = env._lattice(env._scene)
    nodes = [lattice.snap(view)[0] for view in views]
    expected = [r + 20.0 * s for r, s in zip(bov_only, new_shares(nodes))]
    assert weighted == pytest.approx(expected, abs=1e-4)


def test_validation_and_planning_envs_drop_the_term(tmp_path):
    from nbv.planning.config import PlanConfig
    from nbv.planning.plan import planning_env_config
    from nbv.planning.policy import PolicyPlanner
    from scenes.spec import SceneSpec

    trained = config(coverage_reward=100.0)
    validation = validation_env_config(trained, ValidationConfig(validation_scenes=("random:6",)))
    assert validation.coverage_reward == 0.0

    class Trained(PolicyPlanner):
        def __init__(self) -> None:
            self.env_config = trained

    plan = PlanConfig(scene=SceneSpec(scene="test_building"), planner="policy:x", out=tmp_path)
    assert planning_env_config(plan, Trained()).coverage_reward == 0.0


@pytest.mark.parametrize("weight", [-1.0, math.inf, math.nan])
def test_bad_weights_are_refused(weight):
    with pytest.raises(ValueError, match="coverage_reward must be finite and >= 0"):
        config(coverage_reward=weight)


def test_the_command_line_sets_the_weight():
    from nbv.cli.train import parse_train
    from nbv.rl.presets import COVERAGE_REWARD

    assert parse_train(["--coverage-reward", "300", "--out", "run"]).env.coverage_reward == 300.0
    assert parse_train(["--out", "run"]).env.coverage_reward == COVERAGE_REWARD == 100.0
    assert parse_train(["--preset", "paper", "--out", "run"]).env.coverage_reward == 0.0
    assert parse_train(["--coverage-reward", "0", "--out", "run"]).env.coverage_reward == 0.0
