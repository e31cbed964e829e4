"""Planners: each returns valid viewpoints inside the allowed ranges, on one interface."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import pytest
import torch

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.planning.config import PlanSettings
from nbv.planning.planners import CirclePlanner, GreedyBoVPlanner, HemispherePlanner, RandomPlanner
from nbv.planning.policy import PolicyPlanner
from nbv.planning.registry import (
    SHIPPED_PAPER_POLICY,
    SHIPPED_POLICY,
    entry,
    make_planner,
    planner_label,
    split_spec,
)
from nbv.planning.world import PlanningWorld
from nbv.rl.builders import make_loss_module, make_optimizers, make_replay_buffer, make_sac_agent
from nbv.rl.checkpoint import CheckpointError, save_checkpoint
from nbv.rl.config import EnvConfig, LatticeConfig, LoggerConfig, OptimConfig, TrainConfig
from nbv.rl.env import NBVEnv
from nbv.rl.train import write_checkpoint
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes.spec import SceneSet

TEST_BUILDING = SceneSet(scene=("test_building",))
PLAN = PlanSettings()


def tiny_config(**kwargs) -> EnvConfig:
    settings = dict(scenes=TEST_BUILDING, camera=UAVCamera(64, 48), render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32, max_steps=4)
    return EnvConfig(**{**settings, **kwargs})


def tiny_env(seed: int = 0, **kwargs) -> NBVEnv:
    return NBVEnv(tiny_config(**kwargs), seed=seed)


def tiny_world(seed: int = 0, **kwargs) -> PlanningWorld:
    return PlanningWorld(tiny_config(**kwargs), seed=seed)


def in_ranges(view: Viewpoint, config: EnvConfig) -> bool:
    low, high = config.low, config.high
    return (low[0] - 1e-9 <= view.radius <= high[0] + 1e-9 and 0 <= view.azimuth < 2 * math.pi
            and low[2] - 1e-9 <= view.elevation <= high[2] + 1e-9)


@pytest.mark.parametrize("planner", [RandomPlanner(seed=3), CirclePlanner(), GreedyBoVPlanner(candidates=2)])
def test_baselines_return_the_asked_number_of_valid_views(planner):
    world = tiny_world()
    views = planner.plan(world, 3)
    assert len(views) == 3 and all(isinstance(v, Viewpoint) and in_ranges(v, world.env) for v in views)


def test_random_is_seeded_and_circle_is_evenly_spaced():
    world = tiny_world()
    assert RandomPlanner(seed=1).plan(world, 4) == RandomPlanner(seed=1).plan(world, 4)
    assert RandomPlanner(seed=1).plan(world, 4) != RandomPlanner(seed=2).plan(world, 4)
    circle = CirclePlanner().plan(world, 4)
    assert [v.azimuth for v in circle] == pytest.approx([0, math.pi / 2, math.pi, 3 * math.pi / 2])
    assert len(CirclePlanner().plan(world, None)) == 13
    assert world.source.views_rendered == 0 and world.source.setup_seconds == 0.0  # nothing rendered


def test_greedy_picks_the_candidate_of_highest_reward_without_committing_a_candidate(monkeypatch):
    world = tiny_world()
    planner = GreedyBoVPlanner(candidates=3, seed=0)
    rewards = iter([1.0, 5.0, 2.0])
    captured, looked = [], []

    def fake_capture(view):
        captured.append(view)
        return None, torch.zeros(0, 128)

    def fake_reward(self, descriptors, azimuth, elevation, commit=True):
        looked.append(commit)
        return next(rewards)

    monkeypatch.setattr(world.source, "capture", fake_capture)
    monkeypatch.setattr(type(world.bov), "reward", fake_reward)
    views = planner.plan(world, 2)
    assert captured[0] == world.start and views[1] == captured[2]  # the start view, then candidate 1
    assert looked == [False, False, False]


def test_the_world_starts_where_the_env_starts():
    env, world = tiny_env(seed=5), tiny_world(seed=5)
    env.reset()
    assert world.start == env.viewpoint and world.scene == env._scene
    assert world.bov.state_dict().keys() == env.bov.state_dict().keys() and world.bov.seed == env.bov.seed
    assert GreedyBoVPlanner(candidates=2, seed=5).plan(world, 2)[0] == env.viewpoint


def test_hemisphere_is_the_full_scan():
    world = tiny_world()
    views = HemispherePlanner().plan(world, None)
    assert len(views) > 100 and all(v.radius == pytest.approx(2.0) for v in views)
    with pytest.raises(ValueError, match="would cut it"):
        HemispherePlanner().plan(world, 10)


def save_untrained_policy(path, env: NBVEnv) -> None:
    config = TrainConfig(env=env.config, logger=LoggerConfig(out=path.parent))
    actor, critic = make_sac_agent(env.config, config.network)
    loss, _ = make_loss_module(actor, critic, OptimConfig())
    optim_actor, optim_critic = make_optimizers(loss, OptimConfig())
    buffer = make_replay_buffer(config.replay_buffer)
    write_checkpoint(path, config, loss, optim_actor, optim_critic, buffer, 0, 0, None)


def test_policy_planner_from_checkpoint(tmp_path):
    env = tiny_env(max_steps=3)
    save_untrained_policy(tmp_path / "checkpoint.pt", env)
    planner = make_planner(f"policy:{tmp_path / 'checkpoint.pt'}", PLAN)
    assert isinstance(planner, PolicyPlanner) and planner.env_config == env.config  # nested, rebuilt
    world = tiny_world(max_steps=3)
    views = planner.plan(world, None)  # until the episode ends: at most the step cap
    assert 2 <= len(views) <= 4 and all(in_ranges(v, env.config) for v in views)
    assert views[0] == world.start and world.source.views_rendered == len(views)  # on the world's clock
    assert len(planner.plan(tiny_world(), 5)) == 5
    with pytest.raises(ValueError, match="obs_size"):
        planner.plan(PlanningWorld(EnvConfig(scenes=TEST_BUILDING, obs_size=16)), 2)


def test_sampled_policy_is_seeded_and_spread(tmp_path):
    (tmp_path / "run").mkdir()
    save_untrained_policy(tmp_path / "run" / "checkpoint.pt", tiny_env())
    spec = f"policy-sample:{tmp_path / 'run' / 'checkpoint.pt'}"
    sampled = make_planner(spec, PLAN, seed=1)
    assert isinstance(sampled, PolicyPlanner) and sampled.sample
    first = sampled.plan(tiny_world(), 4)
    assert first == make_planner(spec, PLAN, seed=1).plan(tiny_world(), 4)  # seeded: the same draws
    assert first != make_planner(spec, PLAN, seed=2).plan(tiny_world(), 4)
    assert all(in_ranges(v, tiny_config()) for v in first)
    mode_spec = f"policy:{tmp_path / 'run' / 'checkpoint.pt'}"
    mode = make_planner(mode_spec, PLAN, seed=1).plan(tiny_world(), 4)
    assert mode != first and mode == make_planner(mode_spec, PLAN, seed=2).plan(tiny_world(), 4)  # seed-free
    assert planner_label(spec) == "policy-sample-run" and planner_label("greedy") == "greedy"


def test_bad_planner_specs(tmp_path):
    with pytest.raises(ValueError, match="unknown planner"):
        make_planner("best", PLAN)
    with pytest.raises(CheckpointError, match="not found"):
        make_planner("policy:/nonexistent/checkpoint.pt", PLAN)
    flat = {"env": {"scene": ["test_building"], "width": 64, "bov_ranges": 8}, "network": {}}  # old layout
    save_checkpoint(tmp_path / "old.pt", {"config": json.dumps(flat), "loss": {}, "optim_actor": {},
                                          "optim_critic": {}, "buffer": {}, "counters": {}, "rng": {}})
    with pytest.raises(CheckpointError, match="config does not fit.*no field.*bov_ranges"):
        make_planner(f"policy:{tmp_path / 'old.pt'}", PLAN)


def test_policy_file_plans_like_its_checkpoint(tmp_path):
    env = tiny_env(max_steps=3)
    save_untrained_policy(tmp_path / "checkpoint.pt", env)
    policy = tmp_path / "policy.pt"  # written beside every checkpoint: the actor and config alone
    assert policy.stat().st_size < (tmp_path / "checkpoint.pt").stat().st_size
    from_file = make_planner(f"policy:{policy}", PLAN).plan(tiny_world(max_steps=3), 4)
    same = make_planner(f"policy:{tmp_path / 'checkpoint.pt'}", PLAN).plan(tiny_world(max_steps=3), 4)
    assert from_file == same


def same_weights(a: PolicyPlanner, b: PolicyPlanner) -> bool:
    """Whether two policy planners' actors hold the same tensors, bit for bit."""
    first, second = a.actor.state_dict(), b.actor.state_dict()
    return first.keys() == second.keys() and all(torch.equal(first[k], second[k]) for k in first)


def test_shipped_policy_is_the_actor_the_validation_checks_chose():
    round17 = Path(__file__).resolve().parents[3] / "paper_results" / "selection" / "round17"
    chosen = PolicyPlanner(round17 / "policies" / "s3f6000.pt")
    assert same_weights(chosen, PolicyPlanner(SHIPPED_POLICY))  # nbv/planning/shipped/README.md: bit for bit


def test_bare_policy_spec_is_the_shipped_policy():
    assert split_spec("policy") == (entry("policy"), None)  # no checkpoint: the factory takes the shipped one
    assert split_spec("policy-sample:run/policy.pt") == (entry("policy-sample"), "run/policy.pt")
    assert split_spec("random") == (entry("random"), None) and not entry("random").checkpoint
    assert planner_label("policy") == "policy-shipped"
    assert same_weights(make_planner("policy", PLAN), PolicyPlanner(SHIPPED_POLICY))


@pytest.mark.parametrize("path, command", [
    (SHIPPED_POLICY, ["--seed", "1", "--out", "runs/default"]),  # nbv/planning/shipped/README.md
    (SHIPPED_POLICY.parent / "coverage" / "policy.pt", ["--preset", "coverage", "--out", "runs/default"]),
])
def test_shipped_policy_is_its_training_command_and_plans(path, command):
    from common.provenance import config_record
    from nbv.cli.train import parse_train
    from nbv.rl.checkpoint import load_policy
    from nbv.rl.train import with_defaults

    raw = torch.load(path, weights_only=True)  # no pickled code in the shipped file
    assert raw["format"] == "nbv-sac-policy" and path.stat().st_size < 5_000_000
    shipped = with_defaults(load_policy(path)[0])  # older layouts read, settings added since at defaults
    default = config_record(parse_train(command))
    for group in ("env", "reward", "collector", "replay_buffer", "optim", "network", "validation", "members"):
        assert shipped[group] == default[group], group  # the README's command retrains it
    planner = make_planner(f"policy:{path}", PLAN)
    assert isinstance(planner, PolicyPlanner) and planner.env_config.bov.elevation_bands == 2
    world = PlanningWorld(replace(planner.env_config, scenes=TEST_BUILDING, lattice=LatticeConfig()))
    views = planner.plan(world, 3)
    assert len(views) == 3 and all(in_ranges(v, world.env) for v in views)


PAPER_COMMAND = ["--preset", "paper", "--lattice", "--width", "160", "--height", "120", "--spp", "4",
                 "--feature-backend", "opencv", "--out", "runs/paper"]
"""nbv/planning/shipped/paper/README.md's command: the paper's Table 1, rendered and described as the default
is in training (a lattice at 160x120, 4 spp, OpenCV SIFT), so the two differ in their method alone."""


def test_paper_policy_is_the_paper_training_command_and_plans():
    from common.provenance import config_record
    from nbv.cli.train import parse_train
    from nbv.rl.train import with_defaults

    raw = torch.load(SHIPPED_PAPER_POLICY, weights_only=True)
    assert raw["format"] == "nbv-sac-policy" and SHIPPED_PAPER_POLICY.stat().st_size < 5_000_000
    shipped = with_defaults(json.loads(raw["config"]))
    paper = config_record(parse_train(PAPER_COMMAND))
    for group in ("env", "reward", "collector", "replay_buffer", "optim", "network", "validation", "members"):
        assert shipped[group] == paper[group], group  # the README's command retrains it
    planner = make_planner("policy-paper", PLAN)
    env = planner.env_config  # Table 1: absolute actions, azimuth-only ranges, the Bag of Views reward alone
    assert (env.action_mode, env.bov.elevation_bands, env.episode_views) == ("absolute", 1, 0)
    assert shipped["reward"]["coverage"] == 0 and shipped["optim"]["reward_scale"] == 1
    world = PlanningWorld(replace(env, scenes=TEST_BUILDING, lattice=LatticeConfig()))
    views = planner.plan(world, 3)
    assert len(views) == 3 and all(in_ranges(v, world.env) for v in views)
