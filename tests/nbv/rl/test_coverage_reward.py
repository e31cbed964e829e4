"""The coverage reward term: W x the share of the true surface a view is the episode's first to see,
checked against an independent visibility count; a training-only term that only the training builders
give an env, so an env built from an `EnvConfig` alone (planning, validation, scoring) never reads the
true mesh (across a restore: test_env's snapshot test)."""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from common.provenance import config_record
from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.recon.visibility import scene_visibility
from nbv.rl.agent import make_actor
from nbv.rl.builders import make_environment, make_sac_agent
from nbv.rl.config import EnvConfig, LatticeConfig, NetworkConfig, RewardConfig, ValidationConfig
from nbv.rl.env import NBVEnv
from nbv.rl.validate import Validator, evaluation_env_config, validation_env_config
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.spec import SceneSet

ACTIONS = ([0.0, 0.5, 0.3], [0.0, 0.0, 0.0], [0.4, -0.7, -0.2])
"""Relative steps: the second one stays put, so it can see nothing new."""


def config(**kwargs) -> EnvConfig:
    settings = dict(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=4, words=5, sift=FeatureConfig(backend="opencv")),
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
    weighted, same_views = fly(NBVEnv(config(), seed=4, reward_terms=RewardConfig(coverage=50.0)))
    assert [v.as_array().tolist() for v in same_views] == [v.as_array().tolist() for v in views]
    shares = new_shares(views)
    assert shares[0] > 0.01 and shares[1] == 0.0  # a first move sees new surface; staying put does not
    expected = [r + 50.0 * s for r, s in zip(bov_only, shares)]
    assert weighted == pytest.approx(expected, abs=1e-4)


def test_on_a_lattice_the_term_counts_what_the_nodes_see(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(enabled=True, lattice_radii=2, lattice_azimuths=8, lattice_elevations=2)
    bov_only, views = fly(NBVEnv(config(lattice=grid), seed=2))
    env = NBVEnv(config(lattice=grid), seed=2, reward_terms=RewardConfig(coverage=20.0))
    weighted, _ = fly(env)
    lattice = env._lattice(env._scene)
    nodes = [lattice.snap(view)[0] for view in views]
    expected = [r + 20.0 * s for r, s in zip(bov_only, new_shares(nodes))]
    assert weighted == pytest.approx(expected, abs=1e-4)


def test_a_lattice_nodes_reward_is_the_same_in_the_first_and_the_hundredth_episode(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(enabled=True, lattice_radii=1, lattice_azimuths=4, lattice_elevations=2)
    terms = RewardConfig(coverage=20.0)
    env = NBVEnv(config(lattice=grid), seed=3, reward_terms=terms)
    for _ in range(99):
        fly(env)
    start = env._rng.bit_generator.state  # the hundredth episode's start view is drawn from here
    hundredth, views = fly(env)
    first = NBVEnv(config(lattice=grid), seed=3, reward_terms=terms)
    first._rng.bit_generator.state = start
    rewards, same_views = fly(first)  # the same start node and actions, in a fresh env's first episode
    assert [v.as_array().tolist() for v in same_views] == [v.as_array().tolist() for v in views]
    assert hundredth == rewards
    assert len({env._lattice(env._scene).snap(v)[1] for v in views}) > 1  # it moved between nodes
    scene = load_scene("test_building")
    visibility = scene_visibility(scene, UAVCamera(64, 48))
    lattice = env._lattice(env._scene)
    assert len(env._node_seen) == 8  # 100 episodes visited every node: none of their caches grew
    for (_, index), cached in env._node_seen.items():
        i, j, k = np.unravel_index(index, [len(axis) for axis in lattice.axes])
        node = Viewpoint(*(float(axis[n]) for axis, n in zip(lattice.axes, (i, j, k))))
        assert np.array_equal(cached, visibility.seen(viewpoint_to_c2w(node, scene.center()))), index


@pytest.fixture
def no_true_mesh(monkeypatch):
    """The env's ground-truth visibility raises: whatever steps an env then never reads the true mesh."""
    import nbv.rl.env

    def refused(*args, **kwargs):
        raise AssertionError("the env read the true mesh")

    monkeypatch.setattr(nbv.rl.env, "scene_visibility", refused)


def test_an_env_from_an_env_config_alone_never_reads_the_true_mesh(no_true_mesh):
    trained = config()
    for env_config in (trained, evaluation_env_config(trained, trained.scenes)):
        fly(NBVEnv(env_config, seed=1))  # no training-only term: nothing to ray-cast
    fly(make_environment(trained, 1, 1).base_env)  # the training builder without the reward group: none
    with pytest.raises(AssertionError, match="read the true mesh"):
        fly(make_environment(trained, 1, 1, RewardConfig(coverage=10.0)).base_env)


def test_the_validator_scores_on_the_true_mesh_but_its_envs_have_no_term(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(lattice_radii=1, lattice_azimuths=4, lattice_elevations=2)
    validation = ValidationConfig(validation_scenes=("test_building",), validation_episodes=1,
                                  validation_views=2, validation_points=500)
    validator = Validator(config(lattice=grid), validation, NetworkConfig())
    validator.score(make_actor(5, 16, NetworkConfig()).state_dict())
    assert [env.reward_terms for env in validator._envs.values()] == [RewardConfig()]
    assert validation_env_config(config(lattice=grid), validation).lattice.enabled


def test_the_run_config_holds_the_term_in_its_reward_group_not_in_the_env():
    from nbv.cli.train import parse_train

    record = config_record(parse_train(["--preset", "coverage", "--coverage-reward", "30", "--out", "run"]))
    assert record["reward"] == {"coverage": 30.0, "flight": 0.0, "flight_allowance": 0.0,
                                "flight_excess": 0.0, "imitation": 0.0, "teacher_horizon": 3,
                                "teacher_discount": 0.9, "teacher_tolerance": 0.0}
    assert "coverage_reward" not in record["env"]
    assert not any("coverage" in field.name for field in fields(EnvConfig))
    with pytest.raises(TypeError, match="coverage_reward"):
        EnvConfig(scenes=SceneSet(scene=("test_building",)), coverage_reward=30.0)


@pytest.mark.parametrize("weight", [-1.0, math.inf, math.nan])
def test_bad_weights_are_refused(weight):
    with pytest.raises(ValueError, match="coverage_reward must be finite and >= 0"):
        RewardConfig(coverage=weight)


def test_the_command_line_sets_the_weight():
    from nbv.cli.train import parse_train
    from nbv.rl.presets import COVERAGE_REWARD

    assert parse_train(["--coverage-reward", "300", "--out", "run"]).reward.coverage == 300.0
    assert parse_train(["--out", "run"]).reward.coverage == COVERAGE_REWARD == 100.0
    assert parse_train(["--preset", "coverage", "--out", "run"]).reward.coverage == COVERAGE_REWARD
    assert parse_train(["--preset", "paper", "--out", "run"]).reward.coverage == 0.0
    assert parse_train(["--coverage-reward", "0", "--out", "run"]).reward.coverage == 0.0


def test_training_builds_its_env_with_the_reward_group(tmp_path):
    from nbv.rl.train import make_run_collector
    from tests.nbv.rl.test_train import tiny

    run = tiny(tmp_path, 2)
    run = replace(run, env=config(), reward=RewardConfig(coverage=7.0))
    actor, _ = make_sac_agent(run.env, run.network)
    collector, env = make_run_collector(run, actor, 0, None)
    try:
        assert env.reward_terms == RewardConfig(coverage=7.0) and env.config == run.env
    finally:
        collector.shutdown()
