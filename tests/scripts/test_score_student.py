"""`scripts/score_student.py`'s pieces: the regret of a choice and the cross-entropy against hand-worked
scores, the teacher's flights labelled with all its scores, a student fitted to them ranking their best
steps, its flight as a planner, and its blank-image runs folded into its own."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from nbv.planning.world import PlanningWorld
from nbv.rl.config import NetworkConfig, RewardConfig
from nbv.rl.env import NBVEnv
from nbv.rl.expert import CANDIDATES
from scripts import score_student
from tests.nbv.rl.test_bov_observation import config


def test_regret_is_what_the_choice_loses_against_the_teachers_best():
    scores = torch.zeros(2, len(CANDIDATES))
    scores[0, :2] = torch.tensor([1.0, 0.95])  # choice 1: 0.05 lost, a near-tie
    scores[1, 1:3] = torch.tensor([2.0, 1.0])  # choice 2: 1.0 lost
    logits = torch.zeros(2, len(CANDIDATES))
    logits[0, 1] = logits[1, 2] = 1.0
    lost, near = score_student.regret(lambda states: logits, TensorDict({"scores": scores}, [2]))
    assert lost == pytest.approx((0.05 + 1.0) / 2) and near == 0.5


def test_the_cross_entropy_is_least_at_the_teachers_softmax():
    scores = torch.randn(4, len(CANDIDATES), generator=torch.Generator().manual_seed(0))
    batch = TensorDict({"scores": scores}, [4])
    at_target = score_student.cross_entropy(lambda b: scores / 0.5, batch, 0.5)
    entropy = -(torch.softmax(scores / 0.5, -1) * torch.log_softmax(scores / 0.5, -1)).sum(-1).mean()
    assert at_target.item() == pytest.approx(entropy.item(), rel=1e-5)
    assert score_student.cross_entropy(lambda b: -scores, batch, 0.5) > at_target


def test_a_student_fitted_to_the_teachers_flights_ranks_their_steps_and_flies():
    env_config = config(bov_observation=True, episode_views=3, action_mode="orbit")
    env = NBVEnv(env_config, seed=1, reward_terms=RewardConfig(coverage=1.0, flight=0.2))
    flown = score_student.fly(env, 2, 0.0, np.random.default_rng(0), None, "teacher")
    assert [len(states) for states in flown] == [2, 2]  # 3 views: two steps chosen per episode
    data = score_student.stack(flown)
    assert data["scores"].shape == (4, len(CANDIDATES)) and data["bov"].shape[-1] > 0
    torch.manual_seed(0)
    net = score_student.ScoreNet(env_config, NetworkConfig(channels=4, hidden=32, location_hidden=8))
    passes = score_student.fit(net, data, data, 80, 4, 1e-2, 0.5, torch.Generator().manual_seed(0))
    assert passes[-1]["train"] < passes[0]["train"]
    assert passes[-1]["held_regret"] <= 0.1 * max(passes[0]["held_regret"], 1e-3) + 1e-6
    assert passes[-1]["held_near_best"] == 1.0  # it picks a best step in every state it fitted
    world = PlanningWorld(env_config, seed=2)
    views = score_student.StudentPlanner(net).plan(world, 3)
    assert len(views) == 3 and views[0] == world.start


def test_blank_image_runs_become_the_students_blank_coverage():
    run = {"coverage": 90.0, "flight_m": 10.0, "viewpoints": [], "start": []}
    results = {"s": {"summary": {"coverage": {"a": 90.0}}, "runs": {"a": {"runs": {"0": run}, "blank": {}}}},
               "s-blank": {"summary": {"coverage": {"a": 80.0}},
                           "runs": {"a": {"runs": {"0": {**run, "coverage": 80.0}}, "blank": {}}}}}
    score_student.merge_blank(results, "s")
    assert list(results) == ["s"]
    assert results["s"]["summary"]["blank"] == {"a": 80.0}
    assert results["s"]["runs"]["a"]["blank"] == {"0": 80.0}
